#!/usr/bin/env bash
# The paper's FEA round trip with Volcad at every step but the solver:
#   1. export the graded bar as adaptive tetrahedra with a ready static step,
#   2. solve it with CalculiX (ccx),
#   3. convert the .frd result to CSV,
#   4. grade a new design by the simulated displacement (SimulationField).
# Usage: bash assets/examples/fea_roundtrip.sh [WORK_DIR]   (needs ccx on PATH)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
work="${1:-roundtrip}"
volcad="${VOLCAD:-cargo run --release --quiet --bin volcad --}"

rm -rf "$work"
$volcad export fea "$here/graded_bar.rhai" --out "$work" --element c3d4 \
    --min-cell 1 --max-cell 4 --step -0.1
(cd "$work" && OMP_NUM_THREADS=2 ccx -i model > ccx.log)
$volcad fea-result "$work/model.frd" --inp "$work/model.inp" --out "$work/result.csv"
cat > "$work/regrade.rhai" <<'RHAI'
// Red where the bar moved most, blue where it stayed put.
let m = default_materials();
SimulationField("model.inp", "result.csv",
                ["clamp(0, len/0.1, 1)", "1 - clamp(0, len/0.1, 1)"],
                [m.id("red"), m.id("blue")])
RHAI
$volcad info "$work/regrade.rhai"
$volcad eval "$work/regrade.rhai" 0 0 2.4
