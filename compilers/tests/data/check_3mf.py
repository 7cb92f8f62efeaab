"""Open a 3MF with lib3mf's strict reader; print its objects and exit 0,
or print lib3mf's error or warnings and exit 1. Exit 3 when lib3mf is not
installed (the test then says what to install)."""
import sys

try:
    import lib3mf
except ImportError:
    sys.exit(3)

wrapper = lib3mf.get_wrapper()
model = wrapper.CreateModel()
reader = model.QueryReader("3mf")
reader.SetStrictModeActive(True)
try:
    reader.ReadFromFile(sys.argv[1])
except Exception as e:  # lib3mf raises its own ELib3MFException
    print(f"lib3mf strict reader refused {sys.argv[1]}: {e}")
    sys.exit(1)
warnings = [reader.GetWarning(i) for i in range(reader.GetWarningCount())]
if warnings:
    print(f"lib3mf warnings: {warnings}")
    sys.exit(1)
objects = model.GetMeshObjects()
count = 0
while objects.MoveNext():
    mesh = objects.GetCurrentMeshObject()
    print(f"object {mesh.GetName()} {mesh.GetVertexCount()} {mesh.GetTriangleCount()}")
    count += 1
print(f"objects {count}")
