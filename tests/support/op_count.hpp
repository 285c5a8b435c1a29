// arbor (measurement instrument, not part of the library): an operation-counting scalar.
//
// It lives in tests/support, outside include/arbor, because it keeps one global tally and one
// global tape pointer (mutable static state, which the library itself never has). Tests and
// benchmarks include it as "op_count.hpp".
//
// Counted carries a double value and knows whether it is a known constant. Arithmetic folds the
// way a symbolic tool (CasADi's SX) would, and counts every other operation by kind, so that
// instantiating an algorithm with Counted (or Dual<Counted, N>) gives its number of atomic
// operations, comparable with the paper's Table 1.
//
// Folding rules (free, no count):
//   constant op constant            -> constant
//   x * 0, 0 * x, 0 / x             -> constant 0
//   x * 1, 1 * x, x / 1, x + 0, 0 + x, x - 0, +x  -> x (the same node)
//   x - x (the same node)           -> constant 0
//   x / x (the same node)           -> constant 1
// Rewrites (counted as one negation): x * -1, -1 * x, x / -1, 0 - x.
// Everything else counts one operation of its kind: add (+ and -), mul, div, neg, sqrt, sin,
// cos. sincos of a non-constant counts one sin and one cos. Copies are free; comparisons are
// free and compare values.
//
// "The same node" means a value produced by the same operation (or the same input), tracked by
// an identifier: copies share it, every counted operation makes a new one.
//
// The tally is one global (op_tally()), for single-threaded measurement in tests and
// benchmarks; reset it, run the algorithm, read it. Not for target code. The tally counts every
// operation executed; an OpTape records the graph so that OpTape::live() counts only the
// operations the outputs depend on (dead-code elimination, as a symbolic tool's graph would be).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "arbor/core/math.hpp"

namespace arbor::ad {

/// Operation counts by kind.
struct OpTally {
  std::uint64_t add = 0;   ///< additions and subtractions
  std::uint64_t mul = 0;   ///< multiplications
  std::uint64_t div = 0;   ///< divisions
  std::uint64_t neg = 0;   ///< negations
  std::uint64_t sqrt = 0;  ///< square roots
  std::uint64_t sin = 0;   ///< sines
  std::uint64_t cos = 0;   ///< cosines
  /// All operations.
  constexpr std::uint64_t total() const { return add + mul + div + neg + sqrt + sin + cos; }
};

/// Kind of a recorded operation.
enum class OpKind : std::uint8_t { input, add, mul, div, neg, sqrt, sin, cos };

/// Optional record of the operations, to count only the live ones: those an output depends on
/// (what a symbolic tool keeps after dead-code elimination; CasADi's counts are of this kind).
/// Capacity is a template parameter; the storage is the object's, so place large tapes in static
/// storage. Recording stops (and overflowed() turns true) when it is full.
template <std::size_t Capacity>
class OpTape;

namespace detail {
/// What the recorder needs to know of a tape, without its capacity.
struct OpTapeBase {
  struct Entry {
    std::uint64_t a, b;  ///< operand node ids (0: none or constant)
    OpKind kind;         ///< operation
  };
  Entry* entries = nullptr;    ///< storage
  std::size_t capacity = 0;    ///< entries available
  std::size_t size = 0;        ///< entries recorded
  std::uint64_t first_id = 0;  ///< node id of entries[0]
  bool overflow = false;       ///< ran out of space
  void record(std::uint64_t id, OpKind kind, std::uint64_t a, std::uint64_t b) {
    if (size == 0)
      first_id = id;
    if (size >= capacity || id != first_id + size) {
      overflow = true;
      return;
    }
    entries[size++] = Entry{a, b, kind};
  }
};
struct OpCounterState {
  OpTally tally;
  std::uint64_t next_id = 1;
  OpTapeBase* tape = nullptr;
};
inline OpCounterState op_counter_state;
}  // namespace detail

template <std::size_t Capacity>
class OpTape : private detail::OpTapeBase {
 public:
  OpTape() {
    entries = storage_;
    capacity = Capacity;
  }
  OpTape(const OpTape&) = delete;
  OpTape& operator=(const OpTape&) = delete;
  ~OpTape() { stop(); }
  /// Clears the tape and records every new node (inputs and counted operations) from now on.
  void start() {
    size = 0;
    overflow = false;
    detail::op_counter_state.tape = this;
  }
  /// Stops recording.
  void stop() {
    if (detail::op_counter_state.tape == this)
      detail::op_counter_state.tape = nullptr;
  }
  /// True if operations were lost (the counts below are then meaningless).
  bool overflowed() const { return overflow; }
  /// Operations recorded.
  std::size_t recorded() const { return size; }
  /// Operations that the given output node ids depend on, by kind (constants have id 0 and
  /// cost nothing; nodes made before start() count as inputs). `live` is caller-provided
  /// scratch of at least recorded() flags.
  template <class Ids>
  OpTally live(const Ids& output_ids, bool* live) const {
    for (std::size_t i = 0; i < size; ++i)
      live[i] = false;
    auto mark = [&](std::uint64_t id) {
      if (id >= first_id && id < first_id + size)
        live[id - first_id] = true;
    };
    for (std::uint64_t id : output_ids)
      mark(id);
    OpTally t;
    for (std::size_t i = size; i-- > 0;) {
      if (!live[i])
        continue;
      const Entry& e = entries[i];
      mark(e.a);
      mark(e.b);
      switch (e.kind) {
        case OpKind::input:
          break;
        case OpKind::add:
          ++t.add;
          break;
        case OpKind::mul:
          ++t.mul;
          break;
        case OpKind::div:
          ++t.div;
          break;
        case OpKind::neg:
          ++t.neg;
          break;
        case OpKind::sqrt:
          ++t.sqrt;
          break;
        case OpKind::sin:
          ++t.sin;
          break;
        case OpKind::cos:
          ++t.cos;
          break;
      }
    }
    return t;
  }

 private:
  Entry storage_[Capacity];
};

/// The running tally (global; single-threaded use).
inline OpTally& op_tally() {
  return detail::op_counter_state.tally;
}
/// Resets the tally to zero.
inline void reset_op_tally() {
  detail::op_counter_state.tally = OpTally{};
}

/// A double that counts the operations applied to it. Default and double-constructed values
/// are constants; Counted::input(x) makes a symbolic input.
class Counted {
 public:
  constexpr Counted() = default;
  /// A known constant.
  constexpr Counted(double x) : v_(x), id_(0) {}  // NOLINT(google-explicit-constructor)
  /// A symbolic input with value x (a new node).
  static Counted input(double x) { return op(x, OpKind::input, nullptr, 0, 0); }

  /// The numeric value.
  constexpr double value() const { return v_; }
  /// True for a known constant.
  constexpr bool is_constant() const { return id_ == 0; }
  /// Node identifier (0 for constants).
  constexpr std::uint64_t id() const { return id_; }

  friend Counted operator+(const Counted& a) { return a; }
  friend Counted operator-(const Counted& a) {
    if (a.is_constant())
      return Counted(-a.v_);
    return op(-a.v_, OpKind::neg, &op_tally().neg, a.id_, 0);
  }
  friend Counted operator+(const Counted& a, const Counted& b) {
    if (a.is_constant() && b.is_constant())
      return Counted(a.v_ + b.v_);
    if (a.is_zero())
      return b;
    if (b.is_zero())
      return a;
    return op(a.v_ + b.v_, OpKind::add, &op_tally().add, a.id_, b.id_);
  }
  friend Counted operator-(const Counted& a, const Counted& b) {
    if (a.is_constant() && b.is_constant())
      return Counted(a.v_ - b.v_);
    if (b.is_zero())
      return a;
    if (a.is_zero())
      return -b;
    if (a.id_ == b.id_)
      return Counted(0.0);
    return op(a.v_ - b.v_, OpKind::add, &op_tally().add, a.id_, b.id_);
  }
  friend Counted operator*(const Counted& a, const Counted& b) {
    if (a.is_constant() && b.is_constant())
      return Counted(a.v_ * b.v_);
    if (a.is_zero() || b.is_zero())
      return Counted(0.0);
    if (a.is_one())
      return b;
    if (b.is_one())
      return a;
    if (a.is_minus_one())
      return -b;
    if (b.is_minus_one())
      return -a;
    return op(a.v_ * b.v_, OpKind::mul, &op_tally().mul, a.id_, b.id_);
  }
  friend Counted operator/(const Counted& a, const Counted& b) {
    if (a.is_constant() && b.is_constant())
      return Counted(a.v_ / b.v_);
    if (a.is_zero())
      return Counted(0.0);
    if (b.is_one())
      return a;
    if (b.is_minus_one())
      return -a;
    if (a.id_ == b.id_)
      return Counted(1.0);
    return op(a.v_ / b.v_, OpKind::div, &op_tally().div, a.id_, b.id_);
  }
  Counted& operator+=(const Counted& b) { return *this = *this + b; }
  Counted& operator-=(const Counted& b) { return *this = *this - b; }
  Counted& operator*=(const Counted& b) { return *this = *this * b; }
  Counted& operator/=(const Counted& b) { return *this = *this / b; }

  friend bool operator==(const Counted& a, const Counted& b) { return a.v_ == b.v_; }
  friend bool operator<(const Counted& a, const Counted& b) { return a.v_ < b.v_; }
  friend bool operator>(const Counted& a, const Counted& b) { return a.v_ > b.v_; }
  friend bool operator<=(const Counted& a, const Counted& b) { return a.v_ <= b.v_; }
  friend bool operator>=(const Counted& a, const Counted& b) { return a.v_ >= b.v_; }

  friend Counted sqrt(const Counted& a) {
    if (a.is_constant())
      return Counted(std::sqrt(a.v_));
    return op(std::sqrt(a.v_), OpKind::sqrt, &op_tally().sqrt, a.id_, 0);
  }
  friend Counted sin(const Counted& a) {
    if (a.is_constant())
      return Counted(std::sin(a.v_));
    return op(std::sin(a.v_), OpKind::sin, &op_tally().sin, a.id_, 0);
  }
  friend Counted cos(const Counted& a) {
    if (a.is_constant())
      return Counted(std::cos(a.v_));
    return op(std::cos(a.v_), OpKind::cos, &op_tally().cos, a.id_, 0);
  }
  friend Counted abs(const Counted& a) { return a.v_ < 0 ? -a : a; }

 private:
  constexpr Counted(double x, std::uint64_t id) : v_(x), id_(id) {}
  static Counted op(double x, OpKind k, std::uint64_t* tally, std::uint64_t a, std::uint64_t b) {
    auto& st = detail::op_counter_state;
    if (tally)
      ++*tally;
    const std::uint64_t id = st.next_id++;
    if (st.tape)
      st.tape->record(id, k, a, b);
    return Counted(x, id);
  }
  constexpr bool is_zero() const { return id_ == 0 && v_ == 0.0; }
  constexpr bool is_one() const { return id_ == 0 && v_ == 1.0; }
  constexpr bool is_minus_one() const { return id_ == 0 && v_ == -1.0; }

  double v_ = 0.0;
  std::uint64_t id_ = 0;
};

}  // namespace arbor::ad

namespace Eigen {
/// Counted is a real scalar to Eigen (no vectorisation).
template <>
struct NumTraits<arbor::ad::Counted> : NumTraits<double> {
  using Real = arbor::ad::Counted;
  using NonInteger = arbor::ad::Counted;
  using Nested = arbor::ad::Counted;
  using Literal = arbor::ad::Counted;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
    ReadCost = 1,
    AddCost = 1,
    MulCost = 1
  };
  static inline Real epsilon() { return Real(NumTraits<double>::epsilon()); }
  static inline Real dummy_precision() { return Real(NumTraits<double>::dummy_precision()); }
  static inline Real highest() { return Real(NumTraits<double>::highest()); }
  static inline Real lowest() { return Real(NumTraits<double>::lowest()); }
  static inline int digits10() { return NumTraits<double>::digits10(); }
};
}  // namespace Eigen
