// Test support: loader for the Pinocchio reference files in tests/data/reference (format in
// tests/data/reference/README.md), with permutation of joints by name into a robot's order.
#pragma once

#include <Eigen/Core>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace arbor::test {

/// One sample of a reference file: named matrices and world placements of URDF links.
struct ReferenceSample {
  std::map<std::string, Eigen::MatrixXd> values;                            ///< key -> rows x cols
  std::vector<std::pair<std::string, Eigen::Matrix<double, 3, 4>>> frames;  ///< link -> [R|p]
};

/// A whole reference file.
struct ReferenceFile {
  std::string robot;
  int nv = 0;
  std::vector<std::string> joints;  ///< reference joint order
  std::vector<ReferenceSample> samples;
};

/// Reads tests/data/reference/<name>.txt (throws std::runtime_error on a malformed file).
inline ReferenceFile load_reference(const std::string& name) {
  const std::string path = std::string(ARBOR_TEST_DATA_DIR) + "/reference/" + name + ".txt";
  std::ifstream in(path);
  if (!in)
    throw std::runtime_error("cannot open " + path);
  ReferenceFile file;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (line.empty() || line[0] == '#')
      continue;
    std::istringstream ls(line);
    std::string key;
    ls >> key;
    if (key == "robot") {
      ls >> file.robot;
    } else if (key == "nv") {
      ls >> file.nv;
    } else if (key == "joints") {
      std::string j;
      while (ls >> j)
        file.joints.push_back(j);
    } else if (key == "sample") {
      file.samples.emplace_back();
    } else if (key == "frame") {
      std::string link;
      int r = 0, c = 0;
      ls >> link >> r >> c;
      if (r != 3 || c != 4)
        throw std::runtime_error("bad frame record in " + path);
      Eigen::Matrix<double, 3, 4> X;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j)
          ls >> X(i, j);
      file.samples.back().frames.emplace_back(link, X);
    } else {
      int r = 0, c = 0;
      ls >> r >> c;
      Eigen::MatrixXd M(r, c);
      for (int i = 0; i < r; ++i)
        for (int j = 0; j < c; ++j)
          ls >> M(i, j);
      if (!ls)
        throw std::runtime_error("bad record " + key + " in " + path);
      if (file.samples.empty())
        throw std::runtime_error("record before sample in " + path);
      file.samples.back().values[key] = M;
    }
  }
  return file;
}

/// perm[k] = index in the reference order of the robot's joint k (matched by name).
template <class R>
std::vector<int> joint_permutation(const ReferenceFile& file) {
  std::vector<int> perm(R::nv, -1);
  for (int k = 0; k < R::nv; ++k)
    for (std::size_t j = 0; j < file.joints.size(); ++j)
      if (file.joints[j] == R::joint_names[k])
        perm[k] = int(j);
  for (int p : perm)
    if (p < 0)
      throw std::runtime_error("joint missing from the reference file");
  return perm;
}

/// A reference vector in the robot's joint order.
inline Eigen::VectorXd permute_vector(const Eigen::MatrixXd& x, const std::vector<int>& perm) {
  Eigen::VectorXd y(perm.size());
  for (std::size_t k = 0; k < perm.size(); ++k)
    y[k] = x(perm[k], 0);
  return y;
}

/// A reference matrix with rows and columns in the robot's joint order.
inline Eigen::MatrixXd permute_matrix(const Eigen::MatrixXd& M, const std::vector<int>& perm) {
  const int n = int(perm.size());
  Eigen::MatrixXd Y(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      Y(r, c) = M(perm[r], perm[c]);
  return Y;
}

}  // namespace arbor::test
