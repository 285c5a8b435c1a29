#!/usr/bin/env bash
# The demo (from any folder): the paper's experiment, contour-following NMPC of the Kinova Gen3 in
# closed loop (examples/contour: OCP-FD, analytical RBD derivatives, hard tunnel, real-time
# iteration) against MuJoCo as the plant, in the example's default configuration (frozen RK4
# sensitivities, stages from generated code, compiled for this CPU, the feedback bounded to 2 QP
# iterations; the program prints it). Installs the few Debian packages it needs when missing
# (not the cross toolchains, emulators, test or benchmark dependencies: those belong to
# scripts/test.sh), builds one executable, runs it (progress, summary table), writes the CSV log
# and PNG plots.
#   BUILD_DIR    build folder (default build-demo/: configured without tests, so the demo does
#                not need GoogleTest or IPOPT)
#   OUT_DIR      where the log and plots go (default $BUILD_DIR/contour)
#   DEMO=robots  the robot table instead (what the generator made of each robot)
#   DEMO=scenarios  issue 36's scenarios, one run each (nominal; unknown 0.5 kg payload with
#                and without the momentum observer; the payload declared to the controller at run
#                time; unknown damping and armature; noise, filtered and not), their
#                summaries' key lines and scenarios.png side by side
#   DEMO=disturbances  issue 59's disturbances in the middle of the task, without a start phase
#                (--hold 0): a 0.5 kg payload attached at 2 s (and released at 4 s), a 10 N push
#                on the forearm at 3 s, the payload with noise 1e-3 rad, a 1 ms measurement delay,
#                all at once; CONFIG="..." adds options to every run; a table of the limits and
#                the tunnel over every 1 ms plant step and the recovery after each event
#   DEMO=configs the configurations side by side (examples/contour/README.md, "Configurations"):
#                the default, without the feedback bound, the other RK4 sensitivity, and the
#                portable one (exact, expression layer, the compiler's default CPU, no bound), on
#                the nominal plant, the unknown payload and measurement noise: sample median /
#                p99 / max [us], tunnel, failures, statuses, QP iterations (builds three
#                programs: minutes of compiler time each)
# Extra arguments go to the program (`bash scripts/demo.sh --help` lists them).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${BUILD_DIR:-$root/build-demo}"
out="${OUT_DIR:-$build/contour}"

# libmujoco-dev: MuJoCo, the demo's plant (--plant arbor runs arbor's own; without MuJoCo the
# program builds with arbor's plant only)
packages=(cmake make g++ pkg-config libeigen3-dev liburdfdom-dev liburdfdom-tools libtinyxml-dev
          libconsole-bridge-dev libmujoco-dev python3 python3-matplotlib)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "demo: installing ${missing[*]}"
  sudo=""
  if [ "$(id -u)" != 0 ]; then sudo="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=Release -DARBOR_BUILD_TESTS=OFF >/dev/null
if [ "${DEMO:-contour}" = robots ]; then
  cmake --build "$build" -j2 --target robot_table
  exec "$build/examples/robot_table"
fi
start=$(date +%s)
if [ "${DEMO:-contour}" = configs ]; then
  other=contour_exact
  cmake --build "$build" -j"${JOBS:-2}" --target contour $other contour_portable
else
  cmake --build "$build" -j"${JOBS:-2}" --target contour
fi
echo "demo: built in $(($(date +%s) - start)) s"
mkdir -p "$out"
# Debian's python3 has matplotlib; a python3 earlier on PATH (pyenv, venv) may not
py=/usr/bin/python3
[ -x "$py" ] || py=python3
if [ "${DEMO:-contour}" = scenarios ]; then
  names=(nominal payload payload_no_observer payload_known damping_armature noise noise_unfiltered)
  args=("" "--mismatch" "--mismatch --no-observer" "--known-payload" "--damping 0.5 --armature 0.05"
        "--noise 1e-3" "--noise 1e-3 --state-filter 0")
  plots=()
  status=0
  for i in "${!names[@]}"; do
    n=${names[$i]}
    echo "== $n: contour ${args[$i]} $*"
    # shellcheck disable=SC2086
    "$build/examples/contour/contour" --progress 0 --csv "$out/$n.csv" ${args[$i]} "$@" \
      >"$out/$n.txt" || status=$?
    grep -E "start phase \(|tunnel error max|max \|qd\||max \|tau\||final s|failures" "$out/$n.txt"
    plots+=("$n=$out/$n.csv")
  done
  "$py" "$root/examples/contour/plot_scenarios.py" "$out/scenarios.png" "${plots[@]}"
  exit "$status"
fi
if [ "${DEMO:-contour}" = disturbances ]; then
  # Disturbances in the middle of the task (issue 59), no start phase, the demo's configuration
  # plus CONFIG (e.g. CONFIG="--observer"): limits and tunnel over every 1 ms plant step.
  names=(nominal payload_at_2s payload_2s_to_4s push_3s payload_noise delay_1ms all)
  args=("" "--payload-at 2" "--payload-at 2 --payload-release 4" "--push-at 3"
        "--mismatch --noise 1e-3" "--delay 1"
        "--payload-at 2 --payload-release 4 --push-at 3 --noise 1e-3 --delay 1")
  rows=()
  status=0
  for i in "${!names[@]}"; do
    n=${names[$i]}
    echo "== $n: contour --hold 0 ${CONFIG:-} ${args[$i]} $*"
    # shellcheck disable=SC2086
    "$build/examples/contour/contour" --progress 0 --hold 0 --csv "$out/$n.csv" ${CONFIG:-} \
      ${args[$i]} "$@" >"$out/$n.txt" || status=$?
    grep -E "tunnel error max|max \|qd\||max \|tau\||final s|failures|after the" "$out/$n.txt"
    rows+=("$(awk -v sc="$n" '
      /^  tunnel error max/ { tun = $4; for (i = 5; i <= NF; ++i) if ($i == "samples") out = $(i - 1) }
      /^  max \|qd\|/ { qd = $3 }
      /^  max \|tau\|/ { tau = $3 }
      /final s/ { s = $3 }
      /controller failures/ { fail = $NF }
      /back inside rho after|never outside rho/ { ev = ev (ev ? "; " : "") $0 }
      END { gsub(/ +/, " ", ev); gsub(/^ /, "", ev); printf "| %s | %s | %s | %s | %s | %s | %s | %s |\n", sc, tun,
            out, qd, tau, s, fail, ev }' "$out/$n.txt")")
  done
  echo
  echo "| scenario (--hold 0 ${CONFIG:-}) | tunnel max, every 1 ms [mm] | samples with a step outside rho | max \|qd\| / limit, every 1 ms | max \|tau\| / limit | s final | failures | after each event |"
  echo "|---|---:|---:|---:|---:|---:|---:|---|"
  printf "%s\n" "${rows[@]}"
  exit "$status"
fi
if [ "${DEMO:-contour}" = configs ]; then
  exe=$build/examples/contour
  configs=("contour" "contour --feedback-iter 0" "$other" "$other --feedback-iter 0"
           "contour_portable --feedback-iter 0")
  scenarios=("nominal:" "payload:--mismatch" "noise:--noise 1e-3")
  rows=()
  for c in "${configs[@]}"; do
    for sc in "${scenarios[@]}"; do
      name=${sc%%:*}
      log="$out/config_$(echo "$c" | tr ' ' '_')_$name.txt"
      echo "== $c ${sc#*:} $*"
      # shellcheck disable=SC2086
      "$exe/"$c --progress 0 --csv - ${sc#*:} "$@" >"$log" || true
      grep "^configuration" "$log" | head -1 || true
      rows+=("$(awk -v cfg="$c" -v sc="$name" '
        /preparation \+ feedback/ { med = $(NF - 3); p99 = $(NF - 1); mx = $NF }
        /QP iterations per sample/ { qmed = $(NF - 3); qmax = $NF }
        /tunnel error max/ { for (i = 2; i <= NF; ++i) if ($i == "mm") { tun = $(i - 1); break } }
        /controller failures/ { fail = $NF }
        /statuses/ { st = $(NF - 5) " / " $(NF - 3) " / " $(NF - 1) }
        END { printf "| %s | %s | %s | %s | %s | %.2f | %s | %s | %s | %s / %s |\n", cfg, sc, med,
              p99, mx, (med > 0 ? mx / med : 0), tun, fail, st, qmed, qmax }' "$log")")
    done
  done
  echo
  echo "| configuration | plant | sample median [us] | p99 | max | max / median | tunnel [mm] | failures | step_taken / step_limited / other | QP iterations median / max |"
  echo "|---|---|---:|---:|---:|---:|---:|---:|---|---|"
  printf "%s\n" "${rows[@]}"
  echo "(one run each on this machine; the configurations' full summaries: $out/config_*.txt)"
  exit 0
fi
status=0
"$build/examples/contour/contour" --csv "$out/contour.csv" "$@" || status=$?
for a in "$@"; do [ "$a" = --help ] || [ "$a" = -h ] && exit "$status"; done
"$py" "$root/examples/contour/plot.py" "$out/contour.csv" "$out"
exit "$status"
