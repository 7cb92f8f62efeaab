"""Read an Abaqus deck with meshio and print, per element set, how many
elements it holds over all cell blocks (`EALL 1234`), then `cells N`.
Exit 3 when meshio is not installed."""
import sys

try:
    import meshio
except ImportError:
    sys.exit(3)

mesh = meshio.read(sys.argv[1], file_format="abaqus")
for name, blocks in sorted(mesh.cell_sets.items()):
    print(f"{name} {sum(len(b) for b in blocks)}")
print(f"cells {sum(len(b.data) for b in mesh.cells)}")
