// Atomic-operation counts of the paper's Table 1 for one robot: FD, J_FD^c, J_FD^a, ID, J_ID^c,
// J_ID^a, and of its Table 2: H_FD and H_ID by AD (H^c) and by AD over the analytical
// Jacobians (H^a). Each is the total of arbor::ad::Counted's tally for one call with symbolic
// inputs (see tests/support/op_count.hpp for what folds and what counts), in two flavours:
// executed (every operation the code performs) and live (only those the outputs depend on, from
// an OpTape: what a symbolic tool such as CasADi keeps after dead-code elimination, which is
// what the paper's counts are).
//   FD      aba<R>                                     x = (q, v, tau)
//   J_FD^c  aba<R> at Dual<Counted, 3 nv>, one pass    (value and Jacobian)
//   J_FD^a  aba_derivatives<R>                         (value and Jacobian)
//   ID      rnea<R>                                    x = (q, v, a)
//   J_ID^c  rnea<R> at Dual<Counted, 3 nv>, one pass
//   J_ID^a  rnea_derivatives<R>                        (value, Jacobian and M)
#pragma once

#include <arbor/ad/contracted_hessian.hpp>
#include <arbor/ad/dual.hpp>
#include <arbor/ad/rbd_functions.hpp>
#include <cstdint>
#include <memory>
#include <vector>

#include "op_count.hpp"

namespace arbor::bench_ad {

/// Executed and live operation counts of one computation.
struct Count {
  std::uint64_t executed = 0;  ///< every operation performed
  std::uint64_t live = 0;      ///< operations the outputs depend on
};

/// One robot's counts; Hessians only when requested.
struct OpCounts {
  Count fd, jfd_c, jfd_a, id, jid_c, jid_a;
  Count hfd_c, hfd_a, hid_c, hid_a, hfd_s, hid_s;
};

/// Deterministic symbolic inputs (values only matter for the numeric side).
template <int N>
VecN<ad::Counted, N> symbolic_inputs(double offset) {
  VecN<ad::Counted, N> x;
  for (int i = 0; i < N; ++i)
    x[i] = ad::Counted::input(0.3 + offset + 0.37 * i - 0.05 * (i % 5) * i);
  return x;
}

inline constexpr std::size_t kTapeCapacity = std::size_t(1) << 19;
inline ad::OpTape<kTapeCapacity> tape;
inline bool live_flags[kTapeCapacity];

/// Runs f() (which fills the outputs) with a fresh tally and tape; outputs are Eigen objects of
/// Counted whose entries are the outputs.
template <class F, class... Out>
Count measure(F&& f, const Out&... out) {
  ad::reset_op_tally();
  tape.start();
  f();
  tape.stop();
  Count c;
  c.executed = ad::op_tally().total();
  std::vector<std::uint64_t> ids;
  auto collect = [&](const auto& m) {
    for (Eigen::Index i = 0; i < m.size(); ++i)
      ids.push_back(m.data()[i].id());
  };
  (collect(out), ...);
  c.live = tape.overflowed() ? 0 : tape.live(ids, live_flags).total();
  return c;
}

template <class F, class Tag>
Count count_jacobian(const VecN<ad::Counted, F::nin>& x) {
  VecN<ad::Counted, F::nout> y;
  static Eigen::Matrix<ad::Counted, F::nout, F::nin> J;
  auto ws = std::make_unique<ad::JacobianWorkspace<F, Tag, ad::Counted>>();
  const auto f = ad::bind<F>(*ws);
  return measure([&] { f.template value_and_jacobian<Tag>(x, y, J); }, y, J);
}

template <class F, class Tag>
Count count_hessian(const VecN<ad::Counted, F::nin>& x) {
  const VecN<ad::Counted, F::nout> lambda = symbolic_inputs<F::nout>(0.1);
  VecN<ad::Counted, F::nout> y;
  static Eigen::Matrix<ad::Counted, F::nin, F::nin> H;
  auto ws = std::make_unique<ad::HessianWorkspace<F, Tag, ad::Counted>>();
  const auto f = ad::bind<F>(*ws);
  return measure([&] { ad::contracted_hessian<Tag>(f, x, lambda, y, H); }, y, H);
}

template <class R, bool Hessians>
OpCounts op_counts() {
  using FD = ad::ForwardDynamics<R>;
  using ID = ad::InverseDynamics<R>;
  const auto x = symbolic_inputs<3 * R::nv>(0.0);
  OpCounts c;
  VecN<ad::Counted, R::nv> y;
  auto ws = std::make_unique<ad::ValueWorkspace<FD, ad::Counted>>();
  c.fd = measure([&] { ad::bind<FD>(*ws).value(x, y); }, y);
  c.id = measure([&] { ad::bind<ID>(*ws).value(x, y); }, y);
  c.jfd_c = count_jacobian<FD, ad::AutoDiff>(x);
  c.jfd_a = count_jacobian<FD, ad::Analytical>(x);
  c.jid_c = count_jacobian<ID, ad::AutoDiff>(x);
  c.jid_a = count_jacobian<ID, ad::Analytical>(x);
  if constexpr (Hessians) {
    c.hfd_c = count_hessian<FD, ad::AutoDiff>(x);
    c.hfd_a = count_hessian<FD, ad::Analytical>(x);
    c.hid_c = count_hessian<ID, ad::AutoDiff>(x);
    c.hid_a = count_hessian<ID, ad::Analytical>(x);
    c.hfd_s = count_hessian<FD, ad::SecondOrder>(x);
    c.hid_s = count_hessian<ID, ad::SecondOrder>(x);
  }
  return c;
}

#define ARBOR_ROBOT(name, Struct) OpCounts op_counts_##name();
#include <robots/benchmark_robots.inc>
#undef ARBOR_ROBOT

}  // namespace arbor::bench_ad
