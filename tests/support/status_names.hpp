// Test failure messages that print status names instead of numbers: an operator<< for every
// enum with a to_string() found by argument-dependent lookup (arbor::qp::QpStatus, ...), for
// GoogleTest's value printer and, on bare metal, for the minitest console (minitest.hpp).
// A namespace opts in with one line after the include:
//   namespace arbor::qp { using ::arbor::test::status_names::operator<<; }
// Nothing is computed here: the printers run only when a check fails.
#pragma once

#include <concepts>
#include <type_traits>

#if defined(ARBOR_BARE_METAL)
#include "minitest.hpp"
#else
#include <ostream>
#endif

namespace arbor::test::status_names {

/// An enum whose values have a name: to_string(e) is found by ADL and returns a C string.
template <typename E>
concept NamedEnum = std::is_enum_v<E> && requires(E e) {
  { to_string(e) } -> std::convertible_to<const char*>;
};

#if defined(ARBOR_BARE_METAL)
/// Prints the name on the minitest console.
template <NamedEnum E>
::arbor::minitest::Out& operator<<(::arbor::minitest::Out& out, const E& e) {
  return out << to_string(e);
}
#else
/// Prints the name (GoogleTest uses operator<< when ADL finds one).
template <NamedEnum E>
std::ostream& operator<<(std::ostream& os, const E& e) {
  return os << to_string(e);
}
#endif

}  // namespace arbor::test::status_names
