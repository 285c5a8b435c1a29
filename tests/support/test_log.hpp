// Test support: one console for portable tests' progress lines. On bare metal it is minitest's
// console (newlib's printf allocates its buffers); on hosted builds a stream-like wrapper of
// printf. log() << "text " << 3 << ' ' << 1.5e-3 << "\n";
#pragma once

#if defined(ARBOR_BARE_METAL)
#include "minitest.hpp"
namespace arbor::test {
inline ::arbor::minitest::Out& log() {
  return ::arbor::minitest::out();
}
}  // namespace arbor::test
#else
#include <cstdint>
#include <cstdio>
namespace arbor::test {
struct PrintfLog {
  PrintfLog& operator<<(const char* s) { return std::fputs(s, stdout), *this; }
  PrintfLog& operator<<(char c) { return std::fputc(c, stdout), *this; }
  PrintfLog& operator<<(int v) { return std::printf("%d", v), *this; }
  PrintfLog& operator<<(long v) { return std::printf("%ld", v), *this; }
  PrintfLog& operator<<(long long v) { return std::printf("%lld", v), *this; }
  PrintfLog& operator<<(unsigned v) { return std::printf("%u", v), *this; }
  PrintfLog& operator<<(unsigned long v) { return std::printf("%lu", v), *this; }
  PrintfLog& operator<<(unsigned long long v) { return std::printf("%llu", v), *this; }
  PrintfLog& operator<<(double v) { return std::printf("%.3g", v), *this; }
  PrintfLog& operator<<(float v) { return *this << double(v); }
};
inline PrintfLog& log() {
  static PrintfLog l;
  return l;
}
}  // namespace arbor::test
#endif
