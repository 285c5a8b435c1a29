// arbor: the coordinate layouts the per-body actions are written on. An action reads and writes
// "triples": anything indexable by 0, 1, 2 whose entries are one coordinate each, either a
// Vec3<S> (one 3-vector, each coordinate a scalar) or the three coordinate rows of a 3 x L block
// of column vectors (crba and M^-1: a T[3] of Eigen row vectors, or rows_of<j0>(block), a view
// of rows j0..j0+2 of a 6 x L block). Each action is written once on triples; on a block one call
// transforms all L columns. The actions load what they read into locals of the coordinate type
// once and write each output entry once, so no triple object lives across an action. Costs
// nothing at run time by itself.
#pragma once

#include <type_traits>
#include <utility>

#include "arbor/core/config.hpp"
#include "arbor/spatial/fwd.hpp"

namespace arbor::spatial {

namespace detail {
template <class X>
struct CoordOf {
  using type = std::remove_cvref_t<decltype(std::declval<const X&>()[0])>;
};
template <class X>
requires requires {
  typename X::value_type;
}
struct CoordOf<X> {
  using type = typename X::value_type;
};
}  // namespace detail

/// The type of one coordinate of the triple X: S for a Vec3<S>, T for a T[3], the row vector of
/// a rows_of view.
template <class X>
using Coord = typename detail::CoordOf<std::remove_cvref_t<X>>::type;

/// Rows j0, j0 + 1, j0 + 2 of a block (a 6 x L block of column vectors) as a triple of rows, read
/// and written in place. Blk is the block as rows_of received it: an lvalue is held by reference,
/// a temporary (an Eigen Block expression: a pointer and strides) by value.
template <int j0, class Blk>
struct RowsOf {
  using Plain = std::remove_cvref_t<Blk>;
  using value_type = Eigen::Matrix<typename Plain::Scalar, 1, Plain::ColsAtCompileTime>;
  Blk blk;
  ARBOR_INLINE auto operator[](int j) const { return blk.row(j0 + j); }
  ARBOR_INLINE auto operator[](int j) { return blk.row(j0 + j); }
};
template <int j0, class Blk>
ARBOR_INLINE RowsOf<j0, Blk> rows_of(Blk&& blk) {
  return {std::forward<Blk>(blk)};
}

/// dst = x (Accumulate false) or dst += x (true); dst an lvalue or an Eigen row expression.
template <bool Accumulate, class Dst, class T>
ARBOR_INLINE void put(Dst&& dst, const T& x) {
  if constexpr (Accumulate)
    dst += x;
  else
    dst = x;
}

}  // namespace arbor::spatial
