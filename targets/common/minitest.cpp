// minitest runner and console formatting (no printf: newlib's stdio allocates its buffers).
#include "minitest.hpp"

#include <limits>

#include "arbor_target.h"

namespace arbor::minitest {
namespace {
TestInfo* g_first = nullptr;
TestInfo* g_last = nullptr;
int g_current_failures = 0;
}  // namespace

Out& out() {
  static Out o;
  return o;
}

void Out::flush() {
  buf_[n_] = 0;
  if (n_)
    arbor_puts(buf_);
  n_ = 0;
}

Out& Out::operator<<(char c) {
  if (n_ >= int(sizeof buf_) - 1)
    flush();
  buf_[n_++] = c;
  if (c == '\n')
    flush();
  return *this;
}

Out& Out::operator<<(const char* s) {
  if (!s)
    return *this << "(null)";
  while (*s)
    *this << *s++;
  return *this;
}

Out& Out::operator<<(std::string_view s) {
  for (char c : s)
    *this << c;
  return *this;
}

Out& Out::operator<<(unsigned long long v) {
  char d[24];
  int k = 0;
  do {
    d[k++] = char('0' + v % 10);
    v /= 10;
  } while (v);
  while (k)
    *this << d[--k];
  return *this;
}

Out& Out::operator<<(long long v) {
  if (v < 0) {
    *this << '-';
    return *this << static_cast<unsigned long long>(-(v + 1)) + 1ull;
  }
  return *this << static_cast<unsigned long long>(v);
}

// Scientific notation with 10 significant digits, good enough for test messages.
Out& Out::operator<<(double v) {
  if (std::isnan(v))
    return *this << "nan";
  if (std::isinf(v))
    return *this << (v > 0 ? "inf" : "-inf");
  if (v < 0) {
    *this << '-';
    v = -v;
  }
  if (v == 0)
    return *this << "0";
  int e = int(std::floor(std::log10(v)));
  double m = v / std::pow(10.0, e);
  if (m >= 10) {
    m /= 10;
    ++e;
  }
  if (m < 1) {
    m *= 10;
    --e;
  }
  unsigned long long digits = static_cast<unsigned long long>(std::llround(m * 1e9));
  if (digits >= 10000000000ull) {
    digits /= 10;
    ++e;
  }
  char d[11];
  for (int i = 9; i >= 0; --i) {
    d[i] = char('0' + digits % 10);
    digits /= 10;
  }
  *this << d[0] << '.';
  for (int i = 1; i < 10; ++i)
    *this << d[i];
  *this << 'e' << static_cast<long long>(e);
  return *this;
}

Registrar::Registrar(TestInfo* info) {
  if (g_last)
    g_last->next = info;
  else
    g_first = info;
  g_last = info;
}

Failure::Failure(const char* file, int line, const char* text) {
  ++g_current_failures;
  out() << file << ":" << line << ": Failure\n  expected: " << text;
}

Failure::~Failure() {
  out() << "\n";
}

int run_all() {
  int passed = 0, failed = 0;
  for (TestInfo* t = g_first; t; t = t->next) {
    out() << "[ RUN      ] " << t->suite << "." << t->name << "\n";
    g_current_failures = 0;
    arbor_paint_stack();
    t->run();
    const uint32_t stack = arbor_stack_high_water();
    if (g_current_failures == 0) {
      ++passed;
      out() << "[       OK ] ";
    } else {
      ++failed;
      out() << "[  FAILED  ] ";
    }
    out() << t->suite << "." << t->name << " (stack high water " << stack << " bytes)\n";
  }
  out() << passed << " passed, " << failed << " failed\n";
  return failed > 120 ? 120 : failed;
}

}  // namespace arbor::minitest

int main() {
  return arbor::minitest::run_all();
}
