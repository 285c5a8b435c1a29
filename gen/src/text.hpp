// arbor-gen: the two formatting helpers every message of the tree builder uses.
#pragma once

#include <sstream>
#include <string>

namespace arbor::gen {

/// A number in a message: 4 significant digits.
inline std::string fmt(double x) {
  std::ostringstream s;
  s.precision(4);
  s << x;
  return s.str();
}
/// A URDF name in a message: 'name'.
inline std::string quote(const std::string& s) {
  return "'" + s + "'";
}

}  // namespace arbor::gen
