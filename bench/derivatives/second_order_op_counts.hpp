// Operation counts of the contracted second-order derivatives for one robot, with the
// op-counting scalar of the AD layer's reports (tests/support/op_count.hpp; bench/ad/op_counts.hpp
// for executed and live): rnea_second_order_derivatives (outputs tau and the Hessian of
// lambda' ID) and aba_second_order_derivatives (ddq and the Hessian of lambda' FD), the same
// outputs as the H^c and H^a counts of bench/ad (the paper's Table 2).
#pragma once

#include <arbor/derivatives/derivatives.hpp>
#include <cstdio>
#include <memory>

#include "op_counts.hpp"

namespace arbor::bench_so {

template <class R>
void print_op_counts(const char* robot) {
  using C = ad::Counted;
  constexpr int n = R::nv;
  const auto x = bench_ad::symbolic_inputs<3 * n>(0.0);
  const auto lambda = bench_ad::symbolic_inputs<n>(0.1);
  const VecN<C, n> q = x.template segment<n>(0), v = x.template segment<n>(n),
                   a = x.template segment<n>(2 * n);
  auto d = std::make_unique<Data<R, C>>();
  auto dd = std::make_unique<DerivativeData<R, C>>();
  auto so = std::make_unique<SecondOrderData<R, C>>();
  const bench_ad::Count id = bench_ad::measure(
      [&] { rnea_second_order_derivatives<R>(*d, *so, q, v, a, lambda); }, d->tau, so->hessian);
  const bench_ad::Count fd = bench_ad::measure(
      [&] { aba_second_order_derivatives<R>(*d, *dd, *so, q, v, a, lambda); }, d->ddq, so->hessian);
  std::printf("| %s | %d | %llu / %llu | %llu / %llu |\n", robot, n, (unsigned long long)id.live,
              (unsigned long long)id.executed, (unsigned long long)fd.live,
              (unsigned long long)fd.executed);
}

}  // namespace arbor::bench_so
