#!/usr/bin/env bash
# Fuzzes arbor-gen's front end (URDF text -> urdfdom -> tree -> header) with libFuzzer, ASan and
# UBSan, for a bounded time, with the generator's options chosen by the input (gen/src/fuzz.cpp).
# Not part of CI. Usage: scripts/fuzz.sh [SECONDS] (default 60).
# Crashing inputs are written to build-fuzz/artifacts/; the growing corpus to build-fuzz/corpus/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
seconds="${1:-60}"
build="$root/build-fuzz"
bash "$root/scripts/setup.sh"
CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DARBOR_BUILD_FUZZ=ON \
  -DARBOR_BUILD_TESTS=OFF -DARBOR_BUILD_EXAMPLES=OFF >/dev/null
cmake --build "$build" -j2 --target arbor_gen_fuzz
mkdir -p "$build/corpus" "$build/artifacts"
cp -n "$root"/examples/robots/*.urdf "$root"/tests/gen/data/*.urdf "$root"/tests/gen/data/bad/*.urdf \
  "$root"/tests/gen/data/real/*.urdf "$build/corpus/" 2>/dev/null || true
# The same files with an option byte in front (see gen/src/fuzz.cpp): --lock-mimic, --fix-inertia,
# --strict-inertia, --snap 1e-5 and --summary in a few combinations.
for f in "$root"/tests/gen/data/real/*.urdf "$root"/examples/robots/yumi.urdf \
  "$root"/examples/robots/kinova_gen3.urdf; do
  for bits in A E k K; do  # 0x41 0x45 0x6b 0x4b
    [[ -e "$build/corpus/$bits-$(basename "$f")" ]] || { printf '%s' "$bits"; cat "$f"; } \
      >"$build/corpus/$bits-$(basename "$f")"
  done
done
# -detect_leaks=0: urdfdom 3.0.1 itself leaks the links of some models it rejects (a shared_ptr
# cycle inside the model it discards, out of our reach); memory errors and UB are still caught.
ASAN_OPTIONS=detect_leaks=0 "$build/gen/arbor_gen_fuzz" "$build/corpus" -max_total_time="$seconds" -max_len=65536 \
  -detect_leaks=0 \
  -timeout=10 -rss_limit_mb=4096 -artifact_prefix="$build/artifacts/" -print_final_stats=1
