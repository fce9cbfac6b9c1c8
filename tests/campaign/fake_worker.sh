#!/usr/bin/env bash
# A stand-in for `capsim run CASE.toml --out DIR --threads N [--resume] --json` that follows the worker
# contract (campaign/README.md, "The worker contract") without the physics, for the campaign manager's fault tests.
# It "computes" in FAKE_STEPS steps of FAKE_STEP_S seconds, checkpoints to DIR/checkpoint.txt each step,
# exits 3 after checkpointing on SIGTERM/SIGINT, continues from the checkpoint with --resume, and prints
# a JSON result whose min_D12 / max_tau_min are simple functions of Ca with known Ca* and CaH:
#   a/b < 1: min_D12 = 0.02 + 2.0 |Ca - 0.03|   (< 0.05 for |Ca - 0.03| < 0.015)
#   a/b >= 1: min_D12 = 0.02 + 0.5 |Ca - 0.225| (< 0.05 for |Ca - 0.225| < 0.06)
#   max_tau_min = CaH - Ca with CaH = 0.70 / 0.35 (neo-hookean, a/b 0.5 / 2) and 2.5 / 1.4 (skalak)
# Discretisation errors with known limits, for the error estimates (campaign/analysis/uncertainty.h):
#   FAKE_LEVEL_SHIFT=s: CaH of mesh level L is CaH - s 2^-L (first order in h, limit CaH);
#   FAKE_DT_COEF=c: max_tau_min - c dt² (second order in dt; dt = time.dt of the case file, else 0.01,
#   which is also the dt reported).
# The JSON line is printed by `capsim _summary` (the case summary of the real worker) of the capsim binary
# $FAKE_CAPSIM, which the caller must hand over (tests/campaign/test_util.h fake_worker_env): the worker is
# not searched for, since under Slurm it is started by slurmd and wherever the build is its path is not known.
# Faults, chosen by Ca (comma-separated lists, exact text as written in the case file):
#   FAKE_CRASH_CA: SIGSEGV itself; FAKE_FAIL_CA: exit 1 with a message; FAKE_UNSTABLE_CA: status unstable;
#   FAKE_BADINPUT_CA: exit 2. FAKE_LOG: append "done <DIR>" when a case completes.
# Slow cases: FAKE_SLOW_CA (list) on mesh level FAKE_SLOW_LEVEL (any if unset) take FAKE_SLOW_STEP_S (1 s) per step.
set -u
# A stop request from the start on, so that one sent while the worker is still reading its case (a loaded
# machine takes a second for that) is a checkpoint and exit 3 as well, not death by the signal.
stop=0
trap 'stop=1' TERM INT
[ "${1:-}" = "run" ] || { echo "fake_worker: expected 'run'" >&2; exit 2; }
shift
case_file="$1"; shift
out="" resume=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --threads) shift 2 ;;
    --resume) resume=1; shift ;;
    --json) shift ;;
    *) echo "fake_worker: unknown option $1" >&2; exit 2 ;;
  esac
done
[ -f "$case_file" ] || { echo "fake_worker: $case_file: no such file" >&2; exit 2; }
capsim_bin=${FAKE_CAPSIM:-}
[ -n "$capsim_bin" ] || { echo "fake_worker: FAKE_CAPSIM is not set (the capsim binary that prints the result)" >&2; exit 2; }
[ -x "$capsim_bin" ] || { echo "fake_worker: FAKE_CAPSIM=$capsim_bin is not an executable" >&2; exit 2; }
mkdir -p "$out"
get() { awk -F' = ' -v k="$1" '$1 == k { gsub(/"/, "", $2); print $2; exit }' "$case_file"; }
ca=$(get capillary_number); ar=$(get aspect_ratio); law=$(get law); level=$(get level); C=$(get skalak_C)
kb=$(get bending_modulus); kb=${kb:-0}
lambda=$(get viscosity_ratio); lambda=${lambda:-1}
# The initial orientation, echoed as the real worker does (FAKE_DROP_ORIENTATION=1: reported as the defaults, 0,
# whatever the case says — a worker the store must refuse for a tilted case).
tilt=$(get tilt); tilt=${tilt:-0}
azimuth=$(get azimuth); azimuth=${azimuth:-0}
[ "${FAKE_DROP_ORIENTATION:-0}" = 1 ] && tilt=0 azimuth=0
C=${C:-1}
in_list() { local v="$1" list="$2" x; IFS=',' read -ra xs <<< "$list"; for x in "${xs[@]}"; do [ "$x" = "$v" ] && return 0; done; return 1; }

steps=${FAKE_STEPS:-4}
step_s=${FAKE_STEP_S:-0.05}
in_list "$ca" "${FAKE_SLOW_CA:-}" && [ "$level" = "${FAKE_SLOW_LEVEL:-$level}" ] && step_s=${FAKE_SLOW_STEP_S:-1}
step=0
if [ $resume = 1 ]; then
  [ -f "$out/checkpoint.txt" ] || { echo "fake_worker: --resume but no checkpoint in $out" >&2; exit 2; }
  step=$(cat "$out/checkpoint.txt")
  echo "fake_worker: resuming at step $step" >&2
fi
checkpoint() { echo "$step" > "$out/checkpoint.tmp" && mv "$out/checkpoint.tmp" "$out/checkpoint.txt"; }

in_list "$ca" "${FAKE_BADINPUT_CA:-}" && { echo "fake_worker: flow.capillary_number: rejected" >&2; exit 2; }
while [ "$step" -lt "$steps" ]; do
  if [ $stop = 1 ]; then checkpoint; echo "fake_worker: interrupted at step $step" >&2; exit 3; fi
  sleep "$step_s"
  step=$((step + 1))
  checkpoint
  echo "fake_worker: step $step/$steps" >&2
  if [ "$step" = 1 ] && in_list "$ca" "${FAKE_CRASH_CA:-}"; then echo "fake_worker: crashing" >&2; kill -SEGV $$; fi
  if [ "$step" = 1 ] && in_list "$ca" "${FAKE_FAIL_CA:-}"; then echo "fake_worker: singular matrix" >&2; exit 1; fi
done
trap '' TERM INT
status=done
in_list "$ca" "${FAKE_UNSTABLE_CA:-}" && status=unstable
dt=$(get dt)
[[ "$dt" =~ ^[0-9][0-9.e-]*$ ]] || dt=0.01
read -r d h <<< "$(awk -v ca="$ca" -v ar="$ar" -v law="$law" -v L="$level" -v s="${FAKE_LEVEL_SHIFT:-0}" \
                      -v c="${FAKE_DT_COEF:-0}" -v dt="$dt" 'BEGIN {
  if (ar < 1) { d = 0.02 + 2.0 * (ca > 0.03 ? ca - 0.03 : 0.03 - ca); h = (law == "skalak") ? 2.5 : 0.70 }
  else        { d = 0.02 + 0.5 * (ca > 0.225 ? ca - 0.225 : 0.225 - ca); h = (law == "skalak") ? 1.4 : 0.35 }
  printf "%.17g %.17g\n", d, h - s * 2 ^ (-L) - ca - c * dt * dt
}')"
regime=$(awk -v d="$d" 'BEGIN { print (d < 0.05 ? "swinging" : "tumbling") }')
mean=$(awk -v d="$d" 'BEGIN { printf "%.17g", d + 0.1 }')
reason=""
[ $status = unstable ] && reason="NaN in velocity at t=3.2"
# The result line goes through the real summary code (capsim _summary), as `capsim run --json` prints it.
"$capsim_bin" _summary status="$status" reason="$reason" capillary_number="$ca" aspect_ratio="$ar" law="$law" \
  skalak_C="$C" bending_modulus="$kb" viscosity_ratio="$lambda" tilt="$tilt" azimuth="$azimuth" mesh_level="$level" min_D12="$d" max_tau_min="$h" mean_D12="$mean" period=12.5 regime="$regime" \
  volume_drift=1e-4 steps=100 flow_evaluations=200 dt="$dt" t_final=25 wall_s=0.2 threads=1 case_file="$out/case.h5" \
  code_version=fake || exit 1
[ -n "${FAKE_LOG:-}" ] && echo "done $out" >> "$FAKE_LOG"
exit 0
