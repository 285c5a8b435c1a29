// Test-only reference computations (dynamic Eigen); see qp_reference.hpp.
#include "qp_reference.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <vector>

namespace arbor::qp::test {

Kkt kkt_residuals(const RefQp& q, const Eigen::VectorXd& x, const Eigen::VectorXd& lx,
                  const Eigen::VectorXd& la) {
  Kkt k;
  const Eigen::VectorXd z = q.A * x;
  k.dual = (q.H * x + q.g + lx + q.A.transpose() * la).cwiseAbs().maxCoeff();
  k.objective = 0.5 * x.dot(q.H * x) + q.g.dot(x);
  k.pscale = 1 + std::max(x.cwiseAbs().maxCoeff(), z.size() ? z.cwiseAbs().maxCoeff() : 0.0);
  k.dscale = 1 + std::max({(q.H * x).cwiseAbs().maxCoeff(), q.g.cwiseAbs().maxCoeff(),
                           (lx + q.A.transpose() * la).cwiseAbs().maxCoeff()});
  auto check = [&](double zi, double l, double u, double m) {
    k.primal = std::max(k.primal, std::max(l - zi, zi - u));
    if (m != 0) {
      const double d = m > 0 ? std::abs(u - zi) : std::abs(zi - l);
      k.complementarity = std::max(k.complementarity, std::min(std::abs(m), d));
    }
  };
  for (int i = 0; i < x.size(); ++i)
    check(x(i), q.lbx(i), q.ubx(i), lx(i));
  for (int j = 0; j < z.size(); ++j)
    check(z(j), q.lba(j), q.uba(j), la(j));
  return k;
}

EnumResult enumerate_active_sets(const RefQp& q, double tol) {
  const int n = static_cast<int>(q.H.rows());
  const int m = static_cast<int>(q.A.rows());
  const int nz = n + m;
  Eigen::MatrixXd C(nz, n);
  C << Eigen::MatrixXd::Identity(n, n), q.A;
  Eigen::VectorXd lb(nz), ub(nz);
  lb << q.lbx, q.lba;
  ub << q.ubx, q.uba;
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::vector<int> state(nz, 0);  // 0 inactive, 1 lower, 2 upper, 3 equality
  for (int i = 0; i < nz; ++i)
    state[i] = lb(i) == ub(i) ? 3 : 0;
  EnumResult best;
  for (;;) {
    std::vector<int> act;
    for (int i = 0; i < nz; ++i)
      if (state[i] != 0)
        act.push_back(i);
    const int na = static_cast<int>(act.size());
    if (na <= n + m) {
      Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + na, n + na);
      Eigen::VectorXd rhs(n + na);
      K.topLeftCorner(n, n) = q.H;
      rhs.head(n) = -q.g;
      for (int a = 0; a < na; ++a) {
        const int i = act[a];
        K.block(n + a, 0, 1, n) = C.row(i);
        K.block(0, n + a, n, 1) = C.row(i).transpose();
        rhs(n + a) = state[i] == 1 ? lb(i) : ub(i);
      }
      Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(K);
      const Eigen::VectorXd sol = cod.solve(rhs);
      const double scale = 1.0 + rhs.cwiseAbs().maxCoeff();
      if ((K * sol - rhs).cwiseAbs().maxCoeff() <= 1e-9 * scale * (1.0 + K.norm())) {
        const Eigen::VectorXd x = sol.head(n);
        const Eigen::VectorXd z = C * x;
        bool ok = true;
        for (int i = 0; i < nz && ok; ++i)
          ok = z(i) >= lb(i) - tol && z(i) <= ub(i) + tol;
        for (int a = 0; a < na && ok; ++a) {
          const int s = state[act[a]];
          const double lam = sol(n + a);
          if (s == 1)
            ok = lam <= tol;
          if (s == 2)
            ok = lam >= -tol;
        }
        if (ok) {
          const double f = 0.5 * x.dot(q.H * x) + q.g.dot(x);
          if (f < best.objective) {
            best.found = true;
            best.objective = f;
            best.x = x;
          }
        }
      }
    }
    // next working set (odometer over the inequality states, skipping infinite sides)
    int i = 0;
    for (; i < nz; ++i) {
      if (state[i] == 3)
        continue;
      int s = state[i] + 1;
      if (s == 1 && lb(i) == -inf)
        ++s;
      if (s == 2 && ub(i) == inf)
        ++s;
      if (s <= 2) {
        state[i] = s;
        break;
      }
      state[i] = 0;
    }
    if (i == nz)
      break;
  }
  return best;
}

}  // namespace arbor::qp::test
