# Shared by user_tu_counts.sh and user_tu_times.sh (sourced, not run): the robots and algorithms
# of the command line, the generated robot headers, and the compilation of bench/dynamics/
# user_tu.cpp as a user's translation unit (g++ -std=c++20 -O3 -march=native -mno-avx512f
# -DNDEBUG, the method of ../shared/reference/pinocchio_counts.md).
# Expects: root (repository) and build (host build folder) set, the remaining arguments in "$@"
# passed to user_tu_parse_args. Sets: robots, algos (arrays).

# [robots...] [-- algos...]; no robots: ARBOR_BENCHMARK_ROBOTS of the build; no algos: all six.
user_tu_parse_args() {
  robots=()
  algos=()
  while [[ $# -gt 0 && "$1" != "--" ]]; do robots+=("$1"); shift; done
  if [[ $# -gt 0 ]]; then shift; algos=("$@"); fi
  if [[ ${#robots[@]} -eq 0 ]]; then
    local list
    list=$(sed -n 's/^ARBOR_BENCHMARK_ROBOTS:[A-Z]*=//p' "$build/CMakeCache.txt")
    IFS=';' read -r -a robots <<<"$list"
  fi
  [[ ${#algos[@]} -gt 0 ]] || algos=(rnea crba aba minverse rnea_derivatives aba_derivatives)
  local r
  for r in "${robots[@]}"; do
    cmake --build "$build" --target "arbor_robot_${r}_generate" >/dev/null 2>&1
  done
}

declare -A user_tu_algo_id=([rnea]=1 [crba]=2 [aba]=3 [minverse]=4 [rnea_derivatives]=5
  [aba_derivatives]=6)

# include-root robot algo exe [compiler prefix...]: user_tu.cpp against the library under
# include-root/include.
user_tu_compile() {
  local inc_root="$1" r="$2" a="$3" exe="$4" st
  shift 4
  st=$(sed -n "s/^ARBOR_ROBOT_${r}_STRUCT:INTERNAL=//p" "$build/CMakeCache.txt")
  "$@" g++ -std=c++20 -O3 -march=native -mno-avx512f -DNDEBUG -I "$inc_root/include" \
    -I "$build/examples/robots/arbor_robot_${r}_gen" -isystem /usr/include/eigen3 \
    "-DARBOR_UT_ROBOT_HEADER=<robots/$r.hpp>" -DARBOR_UT_STRUCT="$st" \
    -DARBOR_UT_ALGO_ID="${user_tu_algo_id[$a]}" "$root/bench/dynamics/user_tu.cpp" -o "$exe"
}
