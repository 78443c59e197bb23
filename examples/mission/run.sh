#!/usr/bin/env bash
# The worked examples of docs/mission.md: the sweep's gravity-scaled law saved once, then applied
# to three cases a user would bring. Writes examples/mission/law.json and one output file per
# case (examples/mission/*.txt); run from anywhere. GRAVSWEEP_BIN: the binary (default
# build/scheduler/gravsweep).
set -uo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
gs="$(realpath "${GRAVSWEEP_BIN:-$root/build/scheduler/gravsweep}")"
cd "$root" || exit 1  # paths from the root: the law file records its inputs as given
out="examples/mission"
D=""
for level in g9.81 g1.62 g0.1 g0.1_axis g0.01 g0.01_axis g0.001 g0.001_axis; do D="$D data/gravity_sweep/$level"; done
# The law: the sweep's 50 drops, phi m g + kappa g z + m v^2/d1 with the immersion drag that
# `model rank --scaled` names second (GRAVITY.md).
"$gs" model fit $D --model scaled_base+gravity_depth_friction+immersion_drag:shared --baseline scaled_base \
  --no-plot --save "$out/law.json" > "$out/fit.txt" 2>&1 || exit 1
case_run() {  # name, the model verb (predict or infer), then its arguments
  local name="$1" verb="$2"; shift 2
  { echo "\$ gravsweep model $verb --law law.json $*"; (cd "$out" && "$gs" model "$verb" --law law.json "$@" 2>&1);
    echo "(exit $?)"; } > "$out/$name.txt"
}
# A lander's foot pad on a rubble-pile asteroid (Bennu-like, 6e-5 m/s2), 30 cm, 20 kg, 0.1 m/s.
case_run lander predict --gravity 6e-5 --speed 0.1 --diameter 0.3 --mass 20
case_run lander_extrapolated predict --gravity 6e-5 --speed 0.1 --diameter 0.3 --mass 20 --extrapolate
# A sampler head on the Moon, 10 cm, 1 kg, at 0.1 and 0.3 m/s.
case_run moon_sampler predict --gravity 1.62 --speed 0.1 0.3 --diameter 0.1 --mass 1
# A 10 cm rock (1.3 kg, basalt) falling onto dusty regolith at Mars at 1 and 3 m/s.
case_run mars_rock predict --gravity 3.71 --speed 1 3 --diameter 0.1 --mass 1.3
# A 10 cm meteorite (1.3 kg) arriving at Mars at 250 m/s: a cratering impact at Fr 410, far
# beyond the sweep's Fr <= 10 (refused: exit 2).
case_run mars_meteorite predict --gravity 3.71 --speed 250 --diameter 0.1 --mass 1.3
# What one measured depth says about the ground: the Moon sampler at 0.3 m/s sank 4.0 cm, deeper
# than the 3.2 cm the law predicts.
case_run moon_sampler_infer infer --gravity 1.62 --speed 0.3 --diameter 0.1 --mass 1 --zstop 0.04
# The same impact with its duration measured too (0.30 s).
case_run moon_sampler_infer_tstop infer --gravity 1.62 --speed 0.3 --diameter 0.1 --mass 1 --zstop 0.04 --tstop 0.3
echo "wrote $out/law.json and $out/{fit,lander,lander_extrapolated,moon_sampler,mars_rock,mars_meteorite,moon_sampler_infer,moon_sampler_infer_tstop}.txt"
