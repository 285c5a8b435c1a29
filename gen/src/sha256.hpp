// arbor-gen: SHA-256 of the source URDF, for the generated header's banner.
#pragma once

#include <string>
#include <string_view>

namespace arbor::gen {

/// Lower-case hex SHA-256 digest of `bytes` (FIPS 180-4).
std::string sha256_hex(std::string_view bytes);

}  // namespace arbor::gen
