// arbor: compile-time loops. `static_for<N>(f)` calls f(std::integral_constant<int, i>{}) for
// i = 0 .. N-1 in order (a fold expression, fully unrolled); `static_for_reverse` goes N-1 .. 0.
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

}  // namespace arbor
