// IPOPT reference solver for the tests: see ipopt_reference.hpp.
#include "ipopt_reference.hpp"

#include <IpStdCInterface.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <stdexcept>

namespace arbor::test {
namespace {

constexpr double kInf = 1e20;  // IPOPT's "none" (beyond nlp_{lower,upper}_bound_inf = -+1e19)
constexpr double kEps = std::numeric_limits<double>::epsilon();

// Step for w_i with relative size c, rounded so that w_i + h is a floating-point number
// (the difference then carries no representation error).
double fd_step(double wi, double c) {
  const double h = c * std::max(1.0, std::abs(wi));
  volatile double t = wi + h;
  return t - wi;
}

struct Problem {
  const Nlp& nlp;
  const IpoptOptions& opt;
  int n, m;
  long f_count = 0, g_count = 0;
  int last_iter = 0;
  std::exception_ptr error;

  double c_first;  // relative step of the first-derivative stencil

  // Scratch (callbacks are not re-entrant; one Problem per solve).
  std::vector<double> w, gbuf, gp, gm, gp2, gm2, lp, lm, hess;

  Problem(const Nlp& p, const IpoptOptions& o) : nlp(p), opt(o), n(p.n), m(p.m) {
    c_first = o.fd_stencil == 2 ? std::cbrt(kEps) : std::pow(kEps, 0.2);
    w.resize(n);
    gbuf.resize(m);
    gp.resize(m);
    gm.resize(m);
    gp2.resize(m);
    gm2.resize(m);
    lp.resize(n);
    lm.resize(n);
    hess.resize(static_cast<std::size_t>(n) * n);
  }

  double f(const double* x) {
    ++f_count;
    return nlp.f(x);
  }
  void g(const double* x, double* out) {
    ++g_count;
    nlp.g(x, out);
  }

  // Central-difference derivative of a scalar or vector function along coordinate i at x:
  // out[r] = d fun_r / d w_i, with fun(x, values) writing `len` values. Uses this->w as the
  // perturbed point.
  template <typename Fun>
  void fd_direction(const double* x, int i, int len, Fun&& fun, double* out) {
    std::copy(x, x + n, w.begin());
    const double h = fd_step(x[i], c_first);
    if (opt.fd_stencil == 2) {
      w[i] = x[i] + h;
      fun(w.data(), gp.data());
      w[i] = x[i] - h;
      fun(w.data(), gm.data());
      for (int r = 0; r < len; ++r)
        out[r] = (gp[r] - gm[r]) / (2 * h);
    } else {
      w[i] = x[i] + h;
      fun(w.data(), gp.data());
      w[i] = x[i] - h;
      fun(w.data(), gm.data());
      w[i] = x[i] + 2 * h;
      fun(w.data(), gp2.data());
      w[i] = x[i] - 2 * h;
      fun(w.data(), gm2.data());
      for (int r = 0; r < len; ++r) {
        out[r] = (8 * (gp[r] - gm[r]) - (gp2[r] - gm2[r])) / (12 * h);
      }
    }
  }

  void gradient_f(const double* x, double* out) {
    if (nlp.grad_f) {
      nlp.grad_f(x, out);
      return;
    }
    // Scalar function through the vector buffers (gp etc. have size >= 1 here).
    ensure_scalar_buffers();
    for (int i = 0; i < n; ++i) {
      fd_direction(
          x, i, 1, [this](const double* p, double* v) { v[0] = f(p); }, &out[i]);
    }
  }

  // Dense row-major m x n.
  void jacobian_g(const double* x, double* out) {
    if (m == 0)
      return;
    if (nlp.jac_g) {
      nlp.jac_g(x, out);
      return;
    }
    std::vector<double> col(m);
    for (int i = 0; i < n; ++i) {
      fd_direction(
          x, i, m, [this](const double* p, double* v) { g(p, v); }, col.data());
      for (int r = 0; r < m; ++r)
        out[static_cast<std::size_t>(r) * n + i] = col[r];
    }
  }

  void ensure_scalar_buffers() {
    if (gp.empty()) {
      gp.resize(1);
      gm.resize(1);
      gp2.resize(1);
      gm2.resize(1);
    }
  }

  // The parts of the Lagrangian sigma f + lambda^T g whose derivatives are exact (their
  // gradient, differenced once) and those that are finite differences (their values, differenced
  // twice).
  bool f_exact() const { return static_cast<bool>(nlp.grad_f); }
  bool g_exact() const { return static_cast<bool>(nlp.jac_g); }

  // Gradient of the exact parts at x.
  void gradient_exact_parts(const double* x, double sigma, const double* lambda, bool use_g,
                            double* out) {
    std::fill(out, out + n, 0.0);
    if (sigma != 0 && f_exact()) {
      std::vector<double> gf(n);
      nlp.grad_f(x, gf.data());
      for (int i = 0; i < n; ++i)
        out[i] += sigma * gf[i];
    }
    if (use_g && g_exact()) {
      std::vector<double> J(static_cast<std::size_t>(m) * n);
      nlp.jac_g(x, J.data());
      for (int r = 0; r < m; ++r) {
        for (int i = 0; i < n; ++i)
          out[i] += lambda[r] * J[static_cast<std::size_t>(r) * n + i];
      }
    }
  }

  // Value of the finite-difference parts at x.
  double value_fd_parts(const double* x, double sigma, const double* lambda, bool use_g) {
    double v = 0;
    if (sigma != 0 && !f_exact())
      v += sigma * f(x);
    if (use_g && !g_exact()) {
      g(x, gbuf.data());
      for (int r = 0; r < m; ++r)
        v += lambda[r] * gbuf[r];
    }
    return v;
  }

  // Dense Hessian of the Lagrangian into hess (row-major), returned as its lower triangle, row by
  // row: (0,0), (1,0), (1,1), (2,0), ...
  //  - exact parts: central difference of their gradient, column by column, h = cbrt(eps);
  //  - finite-difference parts: second differences of their values (= the 2-point central
  //    difference of the 2-point central gradient), h = eps^(1/4), lower triangle only:
  //      H_ij = [phi(+i,+j) - phi(+i,-j) - phi(-i,+j) + phi(-i,-j)] / (4 h_i h_j)
  //      H_ii = [phi(+2i) - 2 phi(0) + phi(-2i)] / (4 h_i^2)
  //    2 n^2 + 1 evaluations; error O(h^2) + O(eps / h^2) ~ 1e-8 relative.
  void hessian_lagrangian(const double* x, double sigma, const double* lambda, double* values) {
    bool use_g = false;
    for (int r = 0; r < m; ++r)
      use_g = use_g || lambda[r] != 0;
    const bool exact_parts = (sigma != 0 && f_exact()) || (use_g && g_exact());
    const bool fd_parts = (sigma != 0 && !f_exact()) || (use_g && !g_exact());
    std::fill(hess.begin(), hess.end(), 0.0);
    std::vector<double> xp(x, x + n);
    if (exact_parts) {
      const double c = std::cbrt(kEps);
      for (int j = 0; j < n; ++j) {
        const double h = fd_step(x[j], c);
        xp[j] = x[j] + h;
        gradient_exact_parts(xp.data(), sigma, lambda, use_g, lp.data());
        xp[j] = x[j] - h;
        gradient_exact_parts(xp.data(), sigma, lambda, use_g, lm.data());
        xp[j] = x[j];
        for (int i = 0; i < n; ++i) {
          hess[static_cast<std::size_t>(i) * n + j] += (lp[i] - lm[i]) / (2 * h);
        }
      }
      // Symmetrise (the fd part below fills the lower triangle only).
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < i; ++j) {
          hess[static_cast<std::size_t>(i) * n + j] =
              0.5 * (hess[static_cast<std::size_t>(i) * n + j] +
                     hess[static_cast<std::size_t>(j) * n + i]);
        }
      }
    }
    if (fd_parts) {
      const double c = std::pow(kEps, 0.25);
      std::vector<double> h(n);
      for (int i = 0; i < n; ++i)
        h[i] = fd_step(x[i], c);
      auto phi = [&] { return value_fd_parts(xp.data(), sigma, lambda, use_g); };
      const double phi0 = phi();
      for (int i = 0; i < n; ++i) {
        xp[i] = x[i] + 2 * h[i];
        const double pp = phi();
        xp[i] = x[i] - 2 * h[i];
        const double mm = phi();
        xp[i] = x[i];
        hess[static_cast<std::size_t>(i) * n + i] += (pp - 2 * phi0 + mm) / (4 * h[i] * h[i]);
        for (int j = 0; j < i; ++j) {
          double v = 0;
          for (const double si : {1.0, -1.0}) {
            for (const double sj : {1.0, -1.0}) {
              xp[i] = x[i] + si * h[i];
              xp[j] = x[j] + sj * h[j];
              v += si * sj * phi();
            }
          }
          xp[i] = x[i];
          xp[j] = x[j];
          hess[static_cast<std::size_t>(i) * n + j] += v / (4 * h[i] * h[j]);
        }
      }
    }
    int k = 0;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j <= i; ++j)
        values[k++] = hess[static_cast<std::size_t>(i) * n + j];
    }
  }

  template <typename Body>
  Bool guarded(Body&& body) {
    try {
      body();
      return TRUE;
    } catch (...) {
      if (!error)
        error = std::current_exception();
      return FALSE;
    }
  }
};

Problem& P(UserDataPtr p) {
  return *static_cast<Problem*>(p);
}

Bool cb_f(Index, Number* x, Bool, Number* obj, UserDataPtr u) {
  return P(u).guarded([&] { *obj = P(u).f(x); });
}

Bool cb_grad_f(Index, Number* x, Bool, Number* grad, UserDataPtr u) {
  return P(u).guarded([&] { P(u).gradient_f(x, grad); });
}

Bool cb_g(Index, Number* x, Bool, Index m, Number* g, UserDataPtr u) {
  if (m == 0)
    return TRUE;
  return P(u).guarded([&] { P(u).g(x, g); });
}

Bool cb_jac_g(Index n, Number* x, Bool, Index m, Index, Index* iRow, Index* jCol, Number* values,
              UserDataPtr u) {
  if (values == nullptr) {
    int k = 0;
    for (int r = 0; r < m; ++r) {
      for (int i = 0; i < n; ++i, ++k) {
        iRow[k] = r;
        jCol[k] = i;
      }
    }
    return TRUE;
  }
  return P(u).guarded([&] { P(u).jacobian_g(x, values); });
}

Bool cb_h(Index n, Number* x, Bool, Number obj_factor, Index, Number* lambda, Bool, Index,
          Index* iRow, Index* jCol, Number* values, UserDataPtr u) {
  if (values == nullptr) {
    int k = 0;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j <= i; ++j, ++k) {
        iRow[k] = i;
        jCol[k] = j;
      }
    }
    return TRUE;
  }
  return P(u).guarded([&] { P(u).hessian_lagrangian(x, obj_factor, lambda, values); });
}

Bool cb_intermediate(Index, Index iter_count, Number, Number, Number, Number, Number, Number,
                     Number, Number, Index, UserDataPtr u) {
  P(u).last_iter = iter_count;
  return TRUE;
}

std::vector<double> bounds(const std::vector<double>& v, std::size_t size, double none,
                           const char* what) {
  if (v.empty())
    return std::vector<double>(size, none);
  if (v.size() != size) {
    throw std::invalid_argument(std::string("solve_with_ipopt: wrong size of ") + what);
  }
  std::vector<double> out(v);
  for (double& b : out) {
    if (std::isnan(b))
      throw std::invalid_argument(std::string("solve_with_ipopt: NaN in ") + what);
    b = std::clamp(b, -kInf, kInf);
  }
  return out;
}

// The C interface takes char* (not const) in IPOPT 3.11.
char* cstr(const std::string& s) {
  return const_cast<char*>(s.c_str());
}

}  // namespace

std::string ipopt_status_name(int status) {
  switch (status) {
    case Solve_Succeeded:
      return "Solve_Succeeded";
    case Solved_To_Acceptable_Level:
      return "Solved_To_Acceptable_Level";
    case Infeasible_Problem_Detected:
      return "Infeasible_Problem_Detected";
    case Search_Direction_Becomes_Too_Small:
      return "Search_Direction_Becomes_Too_Small";
    case Diverging_Iterates:
      return "Diverging_Iterates";
    case User_Requested_Stop:
      return "User_Requested_Stop";
    case Feasible_Point_Found:
      return "Feasible_Point_Found";
    case Maximum_Iterations_Exceeded:
      return "Maximum_Iterations_Exceeded";
    case Restoration_Failed:
      return "Restoration_Failed";
    case Error_In_Step_Computation:
      return "Error_In_Step_Computation";
    case Maximum_CpuTime_Exceeded:
      return "Maximum_CpuTime_Exceeded";
    case Not_Enough_Degrees_Of_Freedom:
      return "Not_Enough_Degrees_Of_Freedom";
    case Invalid_Problem_Definition:
      return "Invalid_Problem_Definition";
    case Invalid_Option:
      return "Invalid_Option";
    case Invalid_Number_Detected:
      return "Invalid_Number_Detected";
    case Unrecoverable_Exception:
      return "Unrecoverable_Exception";
    case NonIpopt_Exception_Thrown:
      return "NonIpopt_Exception_Thrown";
    case Insufficient_Memory:
      return "Insufficient_Memory";
    case Internal_Error:
      return "Internal_Error";
    default:
      return "unknown IPOPT status " + std::to_string(status);
  }
}

IpoptResult solve_with_ipopt(const Nlp& nlp, const IpoptOptions& options) {
  const int n = nlp.n, m = nlp.m;
  if (n < 1 || m < 0)
    throw std::invalid_argument("solve_with_ipopt: need n >= 1, m >= 0");
  if (!nlp.f)
    throw std::invalid_argument("solve_with_ipopt: f missing");
  if (m > 0 && !nlp.g)
    throw std::invalid_argument("solve_with_ipopt: g missing (m > 0)");
  if (options.fd_stencil != 2 && options.fd_stencil != 4) {
    throw std::invalid_argument("solve_with_ipopt: fd_stencil must be 2 or 4");
  }
  std::vector<double> w_l = bounds(nlp.w_l, n, -kInf, "w_l");
  std::vector<double> w_u = bounds(nlp.w_u, n, kInf, "w_u");
  std::vector<double> g_l = bounds(nlp.g_l, m, -kInf, "g_l");
  std::vector<double> g_u = bounds(nlp.g_u, m, kInf, "g_u");
  std::vector<double> x = nlp.w0.empty() ? std::vector<double>(n, 0.0) : nlp.w0;
  if (static_cast<int>(x.size()) != n)
    throw std::invalid_argument("solve_with_ipopt: w0 size");

  Problem problem(nlp, options);
  const Index nele_jac = m * n;
  const Index nele_hess = n * (n + 1) / 2;
  IpoptProblem ip =
      CreateIpoptProblem(n, w_l.data(), w_u.data(), m, g_l.data(), g_u.data(), nele_jac, nele_hess,
                         0, &cb_f, &cb_g, &cb_grad_f, &cb_jac_g, &cb_h);
  if (ip == nullptr)
    throw std::invalid_argument("solve_with_ipopt: CreateIpoptProblem failed");
  struct Free {
    IpoptProblem p;
    ~Free() { FreeIpoptProblem(p); }
  } free_on_exit{ip};

  bool options_ok = true;
  auto str = [&](const std::string& k, const std::string& v) {
    options_ok = AddIpoptStrOption(ip, cstr(k), cstr(v)) && options_ok;
  };
  auto num = [&](const std::string& k, double v) {
    options_ok = AddIpoptNumOption(ip, cstr(k), v) && options_ok;
  };
  auto integer = [&](const std::string& k, int v) {
    options_ok = AddIpoptIntOption(ip, cstr(k), v) && options_ok;
  };
  str("sb", "yes");  // no banner
  integer("print_level", options.print_level);
  num("tol", options.tol);
  integer("max_iter", options.max_iter);
  // IPOPT relaxes every bound by 1e-8 (relative) by default, which moves an active bound's
  // solution by that much; the reference solves the NLP as stated.
  num("bound_relax_factor", 0.0);
  str("hessian_approximation", options.exact_hessian_by_fd ? "exact" : "limited-memory");
  for (const auto& [k, v] : options.string_options)
    str(k, v);
  for (const auto& [k, v] : options.number_options)
    num(k, v);
  for (const auto& [k, v] : options.int_options)
    integer(k, v);
  if (!options_ok)
    throw std::invalid_argument("solve_with_ipopt: IPOPT rejected an option");
  SetIntermediateCallback(ip, &cb_intermediate);

  IpoptResult result;
  result.g.assign(m, 0.0);
  result.lambda_g.assign(m, 0.0);
  result.z_l.assign(n, 0.0);
  result.z_u.assign(n, 0.0);
  double obj = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const ApplicationReturnStatus status =
      IpoptSolve(ip, x.data(), result.g.data(), &obj, result.lambda_g.data(), result.z_l.data(),
                 result.z_u.data(), &problem);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (problem.error)
    std::rethrow_exception(problem.error);

  result.status = static_cast<int>(status);
  result.success = status == Solve_Succeeded;
  result.status_name = ipopt_status_name(result.status);
  result.w = std::move(x);
  result.objective = obj;
  result.iterations = problem.last_iter;
  result.f_evaluations = problem.f_count;
  result.g_evaluations = problem.g_count;
  return result;
}

}  // namespace arbor::test
