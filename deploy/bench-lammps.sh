#!/usr/bin/env bash
# Side-by-side speed of gravsweep and LAMMPS GRANULAR on the same settled bed.
#
#   deploy/bench-lammps.sh BED.h5 [ROUNDS] [STEPS] [WARMUP]
#
# Installs Debian's lammps + openmpi-bin when `lmp` is missing (apt-get; needs root), converts
# the gravsweep bed (DIR/bed.h5 of `gravsweep run`) into a LAMMPS data file, writes the LAMMPS
# input deck of the same contact model and container (build/bench-lammps/in.bed; the differences
# between the two models are written in the deck), then runs the codes interleaved, ROUNDS times
# (default 3): gravsweep 1 and 2 threads (`gravsweep bench --bed`), LAMMPS serial and
# `mpirun -np 2`. Prints every figure, the medians and the ratios LAMMPS / gravsweep.
# Metric: ns per particle-step = 1e9 x wall time / (steps x grains), STEPS timed steps (default
# 2000) at dt = 1 us after WARMUP steps for LAMMPS (default 500; it starts without contact
# histories); `gravsweep bench` warms up 50 steps itself.
# Timings need an otherwise idle machine; the load average is printed with the results.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bed="${1:?usage: deploy/bench-lammps.sh BED.h5 [ROUNDS] [STEPS] [WARMUP]}"
rounds="${2:-3}"
steps="${3:-2000}"
warmup="${4:-500}"
gravsweep="${GRAVSWEEP:-$root/build/scheduler/gravsweep}"
work="${BENCH_LAMMPS_DIR:-${GRAVSWEEP_BUILD_DIR:-$root/build}/bench-lammps}"  # data file, deck, logs
mkdir -p "$work"

if ! command -v lmp >/dev/null || ! command -v mpirun >/dev/null; then
  echo "installing Debian's lammps and openmpi-bin" >&2
  sudo_cmd=""; [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq lammps openmpi-bin >/dev/null
fi
command -v h5dump >/dev/null || { echo "h5dump (hdf5-tools) is needed to read $bed" >&2; exit 1; }

# --- bed.h5 -> LAMMPS data file (raw little-endian doubles via h5dump, no Python packages) ---
for ds in position_m velocity_m_s omega_rad_s radius_m mass_kg; do
  h5dump -d "/grains/$ds" -b LE -o "$work/$ds.bin" "$bed" >/dev/null
done
attr() { h5dump -a "/container/$1" "$bed" | sed -n 's/.*(0): *//p' | head -1; }
diameter_m="$(attr diameter_m)"
wall_height_m="$(attr wall_height_m)"
gravity_m_s2="$(attr gravity_m_s2)"
python3 - "$work" "$diameter_m" "$wall_height_m" <<'PY'
import array, math, sys
work, diameter, wall_h = sys.argv[1], float(sys.argv[2]), float(sys.argv[3])
def read(name):
    a = array.array("d")
    with open(f"{work}/{name}.bin", "rb") as f:
        a.frombytes(f.read())
    if sys.byteorder != "little":
        a.byteswap()
    return a
x, v, w = read("position_m"), read("velocity_m_s"), read("omega_rad_s")
r, m = read("radius_m"), read("mass_kg")
n = len(r)
half = 0.5 * diameter + 0.005           # box around the cylinder (boundary f f f)
top = max(0.6, wall_h, max(x[3 * i + 2] + r[i] for i in range(n)) + 0.01)
with open(f"{work}/bed.data", "w") as f:
    f.write(f"gravsweep bed converted for LAMMPS: {n} grains, cylinder D = {diameter} m\n\n")
    f.write(f"{n} atoms\n1 atom types\n\n")
    f.write(f"{-half:.6f} {half:.6f} xlo xhi\n{-half:.6f} {half:.6f} ylo yhi\n")
    f.write(f"-0.001 {top:.6f} zlo zhi\n\nAtoms # sphere\n\n")
    for i in range(n):
        rho = m[i] / (4.0 / 3.0 * math.pi * r[i] ** 3)   # mass kept exactly
        f.write(f"{i + 1} 1 {2 * r[i]:.17g} {rho:.17g} "
                f"{x[3*i]:.17g} {x[3*i+1]:.17g} {x[3*i+2]:.17g}\n")
    f.write("\nVelocities\n\n")
    for i in range(n):
        f.write(f"{i + 1} {v[3*i]:.17g} {v[3*i+1]:.17g} {v[3*i+2]:.17g} "
                f"{w[3*i]:.17g} {w[3*i+1]:.17g} {w[3*i+2]:.17g}\n")
print(n)
PY
radius_m="$(python3 -c "print(0.5 * $diameter_m)")"

# --- the input deck ---
cat >"$work/in.bed" <<EOF
# LAMMPS deck of gravsweep's Table 1 Chrono set (Sunday et al. 2021) on a gravsweep bed.
# Written by deploy/bench-lammps.sh from $bed. Usable on its own to cross-check gravsweep:
#   lmp -in in.bed -var steps 2000 -var warmup 500      (or mpirun -np 2 lmp -in in.bed ...)
#
# Where the two models differ (the comparison is of speed; the physics is close, not identical):
# - normal: both Hertz from E = 700 MPa, nu = 0.24. Damping: gravsweep uses Chrono's
#   gn = 2 sqrt(5/6) |beta| sqrt(Sn m*) (exact COR); Debian's LAMMPS 2022 has no
#   'damping coeff_restitution', so 'damping tsuji' (a polynomial fit of the same COR) is used.
# - tangential: gravsweep keeps Chrono's MultiStep spring, projected onto the tangent plane
#   without rescaling, kt = 8 G* sqrt(R* d), Coulomb cap on |F_n| incl. damping with back-solve;
#   'mindlin NULL 1.0 mu' has the same kt from E, nu but rotates and rescales the history and
#   caps on the elastic normal force.
# - rolling: gravsweep applies Chrono/Sunday's constant torque mu_r |F_n| R (no spring, off
#   below 1e-4 m/s and during the first ~16-20 us of a contact); LAMMPS' 'rolling sds' needs a
#   spring (1e5 N/m, stiff so the Coulomb cap mu_r = 0.09 dominates) and a dashpot (0.5).
# - twisting: gravsweep uses Chrono's mu_t = 0.01 with the lens radius; 'twisting marshall' has
#   no free coefficient (mu_t = 2/3 a mu_s): Chrono's 0.01 cannot be set.
# - walls: gravsweep's wall is a true concave cylinder (R* = R Rc/(Rc-R)) and a plane;
#   wall/gran zcylinder uses R* = R. Grain-wall pairs: e = 0.5, mu = 0.45 (explicit pair values).
# - integrator: gravsweep semi-implicit Euler, LAMMPS velocity Verlet (nve/sphere).
units           si
atom_style      sphere
boundary        f f f
processors      * * 1
comm_modify     vel yes
newton          off
read_data       bed.data
pair_style      granular
pair_coeff      * * hertz/material 7.0e8 0.9 0.24 damping tsuji tangential mindlin NULL 1.0 0.16 rolling sds 1.0e5 0.5 0.09 twisting marshall
neighbor        0.001 bin
neigh_modify    delay 0 every 1 check yes
timestep        1.0e-6
fix             integrate all nve/sphere
fix             gravity all gravity $gravity_m_s2 vector 0 0 -1
fix             bottom all wall/gran granular hertz/material 7.0e8 0.5 0.24 damping tsuji tangential mindlin NULL 1.0 0.45 rolling sds 1.0e5 0.5 0.09 twisting marshall zplane 0.0 NULL
fix             side all wall/gran granular hertz/material 7.0e8 0.5 0.24 damping tsuji tangential mindlin NULL 1.0 0.45 rolling sds 1.0e5 0.5 0.09 twisting marshall zcylinder $radius_m
thermo          500
run             \${warmup}
run             \${steps}
EOF

# --- interleaved runs ---
gs_ns() {  # gravsweep ns per particle-step for one thread count (its whole output kept for the host report)
  "$gravsweep" bench --bed "$bed" --steps "$steps" --threads "$1" | tee "$work/gravsweep.$1.out" |
    awk '$1 == "file" {print $4}'
}
lmp_ns() {  # LAMMPS ns per particle-step from the last "Loop time" line
  local log="$work/log.$1.$2"
  (cd "$work" && if [ "$1" -eq 1 ]; then lmp -in in.bed -var steps "$steps" -var warmup "$warmup" -log "$log" -screen none
   else mpirun --allow-run-as-root --oversubscribe -np "$1" lmp -in in.bed -var steps "$steps" -var warmup "$warmup" -log "$log" -screen none; fi) >/dev/null
  grep '^Loop time' "$log" | tail -1 | awk '{print 1e9 * $4 / ($9 * $12)}'
}
declare -a g1 g2 l1 l2
for r in $(seq 1 "$rounds"); do
  g1+=("$(gs_ns 1)"); g2+=("$(gs_ns 2)"); l1+=("$(lmp_ns 1 "$r")"); l2+=("$(lmp_ns 2 "$r")")
  echo "round $r: gravsweep ${g1[-1]} / ${g2[-1]} ns (1 / 2 threads), LAMMPS ${l1[-1]} / ${l2[-1]} ns (1 / 2 ranks)"
done
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR%2) ? a[(NR+1)/2] : 0.5*(a[NR/2]+a[NR/2+1])}'; }
mg1="$(median "${g1[@]}")"; mg2="$(median "${g2[@]}")"; ml1="$(median "${l1[@]}")"; ml2="$(median "${l2[@]}")"
echo
echo "host: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //'), $(nproc) cores; gravsweep $("$gravsweep" --version); LAMMPS $(lmp -h 2>/dev/null | grep -m1 -o '[0-9]* [A-Z][a-z]* [0-9]\{4\}[^$]*' || true)"
echo "medians of $rounds interleaved rounds, $steps steps after $warmup warm-up, dt 1 us, $(wc -l <"$work/bed.data" | awk '{print "bed.data " $1 " lines"}'); load average $(cut -d' ' -f1-3 /proc/loadavg)"
printf '%-28s %10s %10s\n' "ns per particle-step" "1 core" "2 cores"
printf '%-28s %10.1f %10.1f\n' "gravsweep (bench --bed)" "$mg1" "$mg2"
printf '%-28s %10.1f %10.1f\n' "LAMMPS (serial; mpirun -np 2)" "$ml1" "$ml2"
printf '%-28s %9.2fx %9.2fx\n' "ratio LAMMPS / gravsweep" "$(awk "BEGIN {print $ml1 / $mg1}")" "$(awk "BEGIN {print $ml2 / $mg2}")"
printf '%-28s %10s %9.2fx\n' "2-thread speed-up" "gravsweep" "$(awk "BEGIN {print $mg1 / $mg2}")"
printf '%-28s %10s %9.2fx\n' "" "LAMMPS" "$(awk "BEGIN {print $ml1 / $ml2}")"
echo "gravsweep's last round, 2 threads: $(awk '$1 == "file" {printf "force region %s %% of the step, barrier waits %s %% of its thread-time (%s %% after the pair loops)", $8, $9, $10}' "$work/gravsweep.2.out")"
grep '^host' "$work/gravsweep.2.out" || true
