#!/usr/bin/env bash
# The demo (from any folder): the paper's experiment, contour-following NMPC of the Kinova Gen3 in
# closed loop (examples/contour: OCP-FD, analytical RBD derivatives, hard tunnel, real-time
# iteration) against MuJoCo as the plant. Installs the few Debian packages it needs when missing
# (not the cross toolchains, emulators, test or benchmark dependencies: those belong to
# scripts/test.sh), builds one executable, runs it (progress, summary table), writes the CSV log
# and PNG plots.
#   BUILD_DIR    build folder (default build-demo/: configured without tests, so the demo does
#                not need GoogleTest or IPOPT)
#   OUT_DIR      where the log and plots go (default $BUILD_DIR/contour)
#   DEMO=robots  the robot table instead (what the generator made of each robot)
#   DEMO=scenarios  issue 36's scenarios, one run each (nominal; unknown 0.5 kg payload without
#                and with the momentum observer; the payload declared to the controller at run
#                time; unknown damping and armature; noise, plain and filtered), their
#                summaries' key lines and scenarios.png side by side
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
cmake --build "$build" -j2 --target contour
echo "demo: built in $(($(date +%s) - start)) s"
mkdir -p "$out"
# Debian's python3 has matplotlib; a python3 earlier on PATH (pyenv, venv) may not
py=/usr/bin/python3
[ -x "$py" ] || py=python3
if [ "${DEMO:-contour}" = scenarios ]; then
  names=(nominal payload payload_observer payload_known damping_armature noise noise_filtered)
  args=("" "--mismatch" "--mismatch --observer" "--known-payload" "--damping 0.5 --armature 0.05"
        "--noise 1e-3" "--noise 1e-3 --state-filter 0.3 --backoff 1e-3")
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
status=0
"$build/examples/contour/contour" --csv "$out/contour.csv" "$@" || status=$?
for a in "$@"; do [ "$a" = --help ] || [ "$a" = -h ] && exit "$status"; done
"$py" "$root/examples/contour/plot.py" "$out/contour.csv" "$out"
exit "$status"
