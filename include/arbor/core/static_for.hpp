// arbor: compile-time loops. `static_for<N>(f)` calls f(std::integral_constant<int, i>{}) for
// i = 0 .. N-1 in order (a fold expression, fully unrolled); `static_for_reverse` goes N-1 .. 0.
// `static_for_flat` / `static_for_reverse_flat<N, Flatten>` do the same with each call of the body
// flattened when Flatten is true: everything the body calls is inlined into it (ARBOR_FLATTEN).
// For the per-body passes of aba and M^-1 in plain floating point: GCC otherwise leaves large
// bodies out of line with their Eigen assignment loops and block copies (memcpy) out of line too,
// by a budget that depends on everything else the translation unit instantiates, so that the same
// kernel costs different instructions in different units (Atlas M^-1 in double: a tenth apart
// between two units, and flattened about a fifth fewer: bench/RESULTS-regression.md). Not for AD
// scalars, whose bodies are much larger.
#pragma once

#include <type_traits>
#include <utility>

#include "arbor/core/config.hpp"

namespace arbor {

/// Compile-time integer constant used as the argument of static_for bodies.
template <int I>
using index_c = std::integral_constant<int, I>;

namespace detail {
template <class F, int... Is>
ARBOR_INLINE void static_for_impl(F&& f, std::integer_sequence<int, Is...>) {
  (f(index_c<Is>{}), ...);
}
template <int N, class F, int... Is>
ARBOR_INLINE void static_for_reverse_impl(F&& f, std::integer_sequence<int, Is...>) {
  (f(index_c<N - 1 - Is>{}), ...);
}
}  // namespace detail

/// Calls f(index_c<i>{}) for i = 0, 1, ..., N-1.
template <int N, class F>
ARBOR_INLINE void static_for(F&& f) {
  if constexpr (N > 0)
    detail::static_for_impl(f, std::make_integer_sequence<int, N>{});
}

/// Calls f(index_c<i>{}) for i = N-1, ..., 1, 0.
template <int N, class F>
ARBOR_INLINE void static_for_reverse(F&& f) {
  if constexpr (N > 0)
    detail::static_for_reverse_impl<N>(f, std::make_integer_sequence<int, N>{});
}

/// static_for<N>(f), each call of f flattened when Flatten is true.
template <int N, bool Flatten, class F>
ARBOR_INLINE void static_for_flat(F&& f) {
  if constexpr (Flatten)
    static_for<N>([&](auto I) ARBOR_FLATTEN { f(I); });
  else
    static_for<N>(f);
}

/// static_for_reverse<N>(f), each call of f flattened when Flatten is true.
template <int N, bool Flatten, class F>
ARBOR_INLINE void static_for_reverse_flat(F&& f) {
  if constexpr (Flatten)
    static_for_reverse<N>([&](auto I) ARBOR_FLATTEN { f(I); });
  else
    static_for_reverse<N>(f);
}

}  // namespace arbor
