// minitest: a GoogleTest-compatible subset for bare-metal targets, where GoogleTest cannot run
// (no heap, no exceptions, no file system). Test sources include "arbor_test.hpp" and use TEST,
// TEST_F, EXPECT_* / ASSERT_* (TRUE FALSE EQ NE LT LE GT GE NEAR DOUBLE_EQ FLOAT_EQ) and `<<`
// messages; on the host they compile against GoogleTest instead.
//
// The runner prints one line per test with its stack high-water mark, and closes with
// `N passed, N failed`; the exit status is the number of failed tests (at most 120).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>
#include <type_traits>

namespace arbor::minitest {

/// Formats into a fixed buffer and writes to the target's console; never allocates.
class Out {
 public:
  Out& operator<<(const char* s);
  Out& operator<<(std::string_view s);
  Out& operator<<(char c);
  Out& operator<<(bool b) { return *this << (b ? "true" : "false"); }
  Out& operator<<(long long v);
  Out& operator<<(unsigned long long v);
  Out& operator<<(int v) { return *this << static_cast<long long>(v); }
  Out& operator<<(long v) { return *this << static_cast<long long>(v); }
  Out& operator<<(unsigned v) { return *this << static_cast<unsigned long long>(v); }
  Out& operator<<(unsigned long v) { return *this << static_cast<unsigned long long>(v); }
  Out& operator<<(double v);
  Out& operator<<(float v) { return *this << static_cast<double>(v); }
  template <class T>
  Out& operator<<(const T&) {  // values the harness cannot print
    return *this << "<?>";
  }
  void flush();

 private:
  char buf_[256];
  int n_ = 0;
};

/// The console.
Out& out();

/// One registered test.
struct TestInfo {
  const char* suite;
  const char* name;
  void (*run)();
  TestInfo* next;
};

/// Registers a test at static-initialization time.
struct Registrar {
  Registrar(TestInfo* info);
};

/// Reports one failed check; `<<` adds to its message. The destructor ends the line.
class Failure {
 public:
  Failure(const char* file, int line, const char* text);
  ~Failure();
  template <class T>
  Failure& operator<<(const T& v) {
    out() << v;
    return *this;
  }
};

/// Makes `return Voidify() & Failure(...) << msg;` a void expression (for ASSERT_*).
struct Voidify {
  void operator&(const Failure&) const {}
};

/// Base of TEST_F fixtures.
class Test {
 public:
  virtual ~Test() = default;
  virtual void SetUp() {}
  virtual void TearDown() {}
};

template <class A, class B>
void print_pair(const A& a, const B& b) {
  out() << "\n    left:  " << a << "\n    right: " << b;
}

/// ULP-based closeness as GoogleTest's DOUBLE_EQ/FLOAT_EQ (within 4 units in the last place).
template <class T>
bool almost_equal(T a, T b) {
  if (std::isnan(a) || std::isnan(b))
    return false;
  if (a == b)
    return true;
  const T diff = std::fabs(a - b);
  const T scale = std::fmax(std::fabs(a), std::fabs(b));
  return diff <= T(4) * std::numeric_limits<T>::epsilon() * scale;
}

/// Runs every registered test; returns the number of failures.
int run_all();

}  // namespace arbor::minitest

#define ARBOR_MT_CAT2_(a, b) a##b
#define ARBOR_MT_CAT_(a, b) ARBOR_MT_CAT2_(a, b)

#define TEST(suite, name)                                                                         \
  static void suite##_##name##_body();                                                            \
  static ::arbor::minitest::TestInfo suite##_##name##_info{#suite, #name, &suite##_##name##_body, \
                                                           nullptr};                              \
  static ::arbor::minitest::Registrar suite##_##name##_reg(&suite##_##name##_info);               \
  static void suite##_##name##_body()

#define TEST_F(fixture, name)                                                                   \
  struct fixture##_##name##_Test : fixture {                                                    \
    void TestBody();                                                                            \
  };                                                                                            \
  static void fixture##_##name##_run() {                                                        \
    static fixture##_##name##_Test t;                                                           \
    t.SetUp();                                                                                  \
    t.TestBody();                                                                               \
    t.TearDown();                                                                               \
  }                                                                                             \
  static ::arbor::minitest::TestInfo fixture##_##name##_info{#fixture, #name,                   \
                                                             &fixture##_##name##_run, nullptr}; \
  static ::arbor::minitest::Registrar fixture##_##name##_reg(&fixture##_##name##_info);         \
  void fixture##_##name##_Test::TestBody()

#define ARBOR_MT_EXPECT_(cond, text) \
  if (cond) {                        \
  } else                             \
    ::arbor::minitest::Failure(__FILE__, __LINE__, text)
#define ARBOR_MT_ASSERT_(cond, text) \
  if (cond) {                        \
  } else                             \
    return ::arbor::minitest::Voidify() & ::arbor::minitest::Failure(__FILE__, __LINE__, text)

#define ARBOR_MT_CMP_(kind, a, b, op)               \
  ARBOR_MT_##kind##_(((a)op(b)), #a " " #op " " #b) \
      << (::arbor::minitest::print_pair((a), (b)), "\n    ")

#define EXPECT_TRUE(c) ARBOR_MT_EXPECT_(static_cast<bool>(c), #c " is true")
#define EXPECT_FALSE(c) ARBOR_MT_EXPECT_(!static_cast<bool>(c), #c " is false")
#define ASSERT_TRUE(c) ARBOR_MT_ASSERT_(static_cast<bool>(c), #c " is true")
#define ASSERT_FALSE(c) ARBOR_MT_ASSERT_(!static_cast<bool>(c), #c " is false")
#define EXPECT_EQ(a, b) ARBOR_MT_CMP_(EXPECT, a, b, ==)
#define EXPECT_NE(a, b) ARBOR_MT_CMP_(EXPECT, a, b, !=)
#define EXPECT_LT(a, b) ARBOR_MT_CMP_(EXPECT, a, b, <)
#define EXPECT_LE(a, b) ARBOR_MT_CMP_(EXPECT, a, b, <=)
#define EXPECT_GT(a, b) ARBOR_MT_CMP_(EXPECT, a, b, >)
#define EXPECT_GE(a, b) ARBOR_MT_CMP_(EXPECT, a, b, >=)
#define ASSERT_EQ(a, b) ARBOR_MT_CMP_(ASSERT, a, b, ==)
#define ASSERT_NE(a, b) ARBOR_MT_CMP_(ASSERT, a, b, !=)
#define ASSERT_LT(a, b) ARBOR_MT_CMP_(ASSERT, a, b, <)
#define ASSERT_LE(a, b) ARBOR_MT_CMP_(ASSERT, a, b, <=)
#define ASSERT_GT(a, b) ARBOR_MT_CMP_(ASSERT, a, b, >)
#define ASSERT_GE(a, b) ARBOR_MT_CMP_(ASSERT, a, b, >=)
#define EXPECT_NEAR(a, b, tol)                                                                    \
  ARBOR_MT_EXPECT_(std::fabs(double(a) - double(b)) <= double(tol), "|" #a " - " #b "| <= " #tol) \
      << (::arbor::minitest::print_pair(double(a), double(b)), "\n    ")
#define ASSERT_NEAR(a, b, tol)                                                                    \
  ARBOR_MT_ASSERT_(std::fabs(double(a) - double(b)) <= double(tol), "|" #a " - " #b "| <= " #tol) \
      << (::arbor::minitest::print_pair(double(a), double(b)), "\n    ")
#define EXPECT_DOUBLE_EQ(a, b)                                                               \
  ARBOR_MT_EXPECT_(::arbor::minitest::almost_equal<double>((a), (b)), #a " == " #b " (ULP)") \
      << (::arbor::minitest::print_pair(double(a), double(b)), "\n    ")
#define EXPECT_FLOAT_EQ(a, b)                                                               \
  ARBOR_MT_EXPECT_(::arbor::minitest::almost_equal<float>((a), (b)), #a " == " #b " (ULP)") \
      << (::arbor::minitest::print_pair(double(a), double(b)), "\n    ")
#define SCOPED_TRACE(msg) ((void)0)
