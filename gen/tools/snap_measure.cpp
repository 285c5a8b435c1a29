// What `arbor-gen --snap` does to a robot: the model change on the reference samples, and the
// work it saves. Built and run by gen/tools/snap_measure.sh, which generates the two headers
// (<robots/plain.hpp> with struct Plain, <robots/snapped.hpp> with struct Snapped).
//
//   snap_measure diff REFERENCE.txt   max relative difference of M and tau = rnea(q, v, a)
//                                      between the models, and of each against the reference
//   snap_measure run ALGO MODEL N     N calls of rnea|aba|crba on plain|snapped (for callgrind)
#include <arbor/dynamics/dynamics.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <robots/plain.hpp>
#include <robots/snapped.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace {

using Plain = arbor::robots::Plain;
using Snapped = arbor::robots::Snapped;
static_assert(Plain::nv == Snapped::nv);
constexpr int n = Plain::nv;
using Vec = Eigen::Matrix<double, n, 1>;
using Mat = Eigen::Matrix<double, n, n>;

struct Sample {
  std::map<std::string, std::vector<double>> values;
};

std::vector<Sample> read_reference(const char* path, std::vector<std::string>& joints) {
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "cannot read %s\n", path);
    std::exit(2);
  }
  std::vector<Sample> samples;
  for (std::string line; std::getline(in, line);) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "joints") {
      for (std::string j; s >> j;)
        joints.push_back(j);
    } else if (key == "sample") {
      samples.emplace_back();
    } else if (!samples.empty() && key != "frame" && !key.empty() && key[0] != '#') {
      int rows = 0, cols = 0;
      s >> rows >> cols;
      std::vector<double> v(std::size_t(rows * cols));
      for (double& x : v)
        s >> x;
      samples.back().values[key] = v;
    }
  }
  return samples;
}

/// Reference vector / matrix permuted into our joint order (by name).
Vec vec(const std::vector<double>& v, const std::vector<int>& perm) {
  Vec r;
  for (int i = 0; i < n; ++i)
    r[i] = v[std::size_t(perm[i])];
  return r;
}
Mat mat(const std::vector<double>& v, const std::vector<int>& perm) {
  Mat r;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      r(i, j) = v[std::size_t(perm[i] * n + perm[j])];
  return r;
}

double rel(const auto& a, const auto& b) {
  return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff();
}

int diff(const char* path) {
  std::vector<std::string> joints;
  const auto samples = read_reference(path, joints);
  std::vector<int> perm(n, -1);
  for (int i = 0; i < n; ++i)
    for (std::size_t k = 0; k < joints.size(); ++k)
      if (joints[k] == Plain::joint_names[i])
        perm[i] = int(k);
  for (int p : perm)
    if (p < 0) {
      std::fprintf(stderr, "joint names differ from the reference\n");
      return 2;
    }
  auto dp = std::make_unique<arbor::Data<Plain, double>>();
  auto ds = std::make_unique<arbor::Data<Snapped, double>>();
  double m_ps = 0, t_ps = 0, m_pr = 0, t_pr = 0, m_sr = 0, t_sr = 0;
  for (const auto& s : samples) {
    const Vec q = vec(s.values.at("q"), perm), v = vec(s.values.at("v"), perm),
              a = vec(s.values.at("a"), perm);
    const Mat Mref = mat(s.values.at("crba"), perm);
    const Vec tref = vec(s.values.at("rnea"), perm);
    const Mat Mp = arbor::crba(*dp, q);
    const Mat Ms = arbor::crba(*ds, q);
    const Vec tp = arbor::rnea(*dp, q, v, a);
    const Vec ts = arbor::rnea(*ds, q, v, a);
    m_ps = std::max(m_ps, rel(Ms, Mp));
    t_ps = std::max(t_ps, rel(ts, tp));
    m_pr = std::max(m_pr, rel(Mp, Mref));
    t_pr = std::max(t_pr, rel(tp, tref));
    m_sr = std::max(m_sr, rel(Ms, Mref));
    t_sr = std::max(t_sr, rel(ts, tref));
  }
  std::printf("samples %zu; max |difference| / max |entry| over the samples:\n", samples.size());
  std::printf("  snapped vs plain:     M %.3g  tau %.3g\n", m_ps, t_ps);
  std::printf("  plain vs reference:   M %.3g  tau %.3g\n", m_pr, t_pr);
  std::printf("  snapped vs reference: M %.3g  tau %.3g\n", m_sr, t_sr);
  return 0;
}

template <class R>
int run(const std::string& algo, long calls) {
  auto d = std::make_unique<arbor::Data<R, double>>();
  Vec q, v, a;
  for (int i = 0; i < n; ++i) {
    q[i] = 0.1 * (i + 1) - 0.35;
    v[i] = 0.2 - 0.05 * i;
    a[i] = 0.3 * ((i % 3) - 1);
  }
  double sink = 0;
  for (long k = 0; k < calls; ++k) {
    asm volatile("" : : "r"(q.data()) : "memory");  // inputs may have changed
    if (algo == "rnea")
      sink += arbor::rnea(*d, q, v, a)[0];
    else if (algo == "aba")
      sink += arbor::aba(*d, q, v, a)[0];
    else if (algo == "crba")
      sink += arbor::crba(*d, q)(0, 0);
    else
      return 2;
  }
  std::printf("%g\n", sink);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  if (mode == "diff" && argc == 3)
    return diff(argv[2]);
  if (mode == "run" && argc == 5) {
    const long calls = std::atol(argv[4]);
    if (std::string(argv[3]) == "plain")
      return run<Plain>(argv[2], calls);
    if (std::string(argv[3]) == "snapped")
      return run<Snapped>(argv[2], calls);
  }
  std::fprintf(stderr, "usage: snap_measure diff REF | run rnea|aba|crba plain|snapped N\n");
  return 2;
}
