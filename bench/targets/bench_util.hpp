// Measurement helpers for bare-metal benchmarks (see rbd_bench.cpp.in). Output lines:
//   BENCH <robot> <scalar> <algorithm> <instructions/call> <stack bytes/call>
#pragma once

#include <cstdint>

#include "arbor_target.h"

namespace arbor::bench {

/// Console output without printf (newlib's stdio would allocate).
inline void put(const char* s) {
  arbor_puts(s);
}
inline void put(std::uint64_t v) {
  char buf[24];
  int n = 23;
  buf[n] = 0;
  do {
    buf[--n] = char('0' + v % 10);
    v /= 10;
  } while (v);
  arbor_puts(buf + n);
}

inline int& failure_count() {
  static int n = 0;
  return n;
}
inline int failures() {
  return failure_count();
}

/// Instructions per SysTick tick, measured on a loop of known instruction count.
inline std::uint64_t& insn_per_tick() {
  static std::uint64_t v = 0;
  return v;
}

__attribute__((noinline)) inline void spin(std::uint32_t n) {
  // Two instructions per iteration (subs + bne).
  __asm volatile(
      "1: subs %0, %0, #1 \n"
      "   bne 1b          \n"
      : "+r"(n)
      :
      : "cc");
}

inline void calibrate() {
  arbor_ticks_start();
  const std::uint32_t n = 2000000;  // 4e6 instructions
  const std::uint64_t t0 = arbor_ticks();
  spin(n);
  const std::uint64_t t1 = arbor_ticks();
  const std::uint64_t ticks = t1 - t0;
  insn_per_tick() = ticks ? (2ull * n + ticks / 2) / ticks : 0;
  put("CALIBRATION ticks=");
  put(ticks);
  put(" for 4000000 instructions: ");
  put(insn_per_tick());
  put(" instructions per tick\n");
  if (insn_per_tick() == 0)
    ++failure_count();
}

class Measure {
 public:
  Measure(const char* robot, const char* scalar) : robot_(robot), scalar_(scalar) {}

  template <class F>
  void run(const char* algo, F f) {
    f();  // warm-up
    // Stack used by one call: paint, call once, read the high-water mark against a baseline.
    arbor_paint_stack();
    const std::uint32_t base = arbor_stack_high_water();
    call(f);
    const std::uint32_t stack = arbor_stack_high_water() - base;
    // Instructions: ticks of 16, 32 and 48 calls; per-call = difference of run lengths (so the
    // constant overhead cancels), which must be the same twice (linearity).
    const std::uint64_t t16 = ticks_for(f, 16), t32 = ticks_for(f, 32), t48 = ticks_for(f, 48);
    const std::uint64_t d1 = t32 - t16, d2 = t48 - t32;
    const std::uint64_t per_call = (d1 + d2) * insn_per_tick() / 32;
    const std::uint64_t again = ticks_for(f, 32);
    const bool linear = (d1 > d2 ? d1 - d2 : d2 - d1) <= 2 + d1 / 200;  // 0.5% + 2 ticks
    // One tick is 40 instructions: a run can start anywhere within a tick, so equal work reads
    // the same count to within one tick.
    const bool repeatable = (again > t32 ? again - t32 : t32 - again) <= 1;
    put("BENCH ");
    put(robot_);
    put(" ");
    put(scalar_);
    put(" ");
    put(algo);
    put(" ");
    put(per_call);
    put(" ");
    put(std::uint64_t(stack));
    if (!linear)
      put(" NOT-LINEAR");
    if (!repeatable)
      put(" NOT-REPEATABLE");
    put("\n");
    if (!linear || !repeatable)
      ++failure_count();
  }

 private:
  template <class F>
  __attribute__((noinline)) static void call(F& f) {
    f();
  }
  template <class F>
  static std::uint64_t ticks_for(F& f, int n) {
    const std::uint64_t t0 = arbor_ticks();
    for (int i = 0; i < n; ++i)
      call(f);
    return arbor_ticks() - t0;
  }
  const char* robot_;
  const char* scalar_;
};

/// Deterministic inputs within the joint ranges (no libm: a small LCG).
template <class R, class V>
void fill_inputs(V& q, V& v, V& a, V& tau) {
  std::uint32_t s = 12345;
  auto next = [&] {
    s = s * 1664525u + 1013904223u;
    return double(s >> 8) / double(1u << 24) * 2.0 - 1.0;  // [-1, 1)
  };
  using S = typename V::Scalar;
  for (int i = 0; i < R::nv; ++i) {
    q[i] = S(next());
    v[i] = S(next());
    a[i] = S(next());
    tau[i] = S(10 * next());
  }
}

}  // namespace arbor::bench
