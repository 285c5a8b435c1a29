// arbor-gen: the 3x3 routines too long to inline (symmetric eigen-decomposition, rotation
// distance); each costs O(1) flops.
#include "math3.hpp"

#include <algorithm>

namespace arbor::gen {

SymEigen eigen_sym(Mat3 A) {
  Mat3 V{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
  for (int sweep = 0; sweep < 64; ++sweep) {
    const double off = std::abs(A[0][1]) + std::abs(A[0][2]) + std::abs(A[1][2]);
    if (off == 0)
      break;
    for (int p = 0; p < 2; ++p) {
      for (int q = p + 1; q < 3; ++q) {
        if (A[p][q] == 0)
          continue;
        const double theta = (A[q][q] - A[p][p]) / (2 * A[p][q]);
        const double t =
            (theta >= 0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; ++k) {  // A <- A J
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq;
          A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; ++k) {  // A <- J^T A
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk;
          A[q][k] = s * apk + c * aqk;
        }
        A[p][q] = A[q][p] = 0;
        for (int k = 0; k < 3; ++k) {  // V <- V J
          const double vkp = V[k][p], vkq = V[k][q];
          V[k][p] = c * vkp - s * vkq;
          V[k][q] = s * vkp + c * vkq;
        }
      }
    }
  }
  std::array<int, 3> order{0, 1, 2};
  std::sort(order.begin(), order.end(), [&](int a, int b) { return A[a][a] < A[b][b]; });
  SymEigen e;
  for (int j = 0; j < 3; ++j) {
    e.values[j] = A[order[j]][order[j]];
    for (int i = 0; i < 3; ++i)
      e.V[i][j] = V[i][order[j]];
  }
  return e;
}

Mat3 from_eigen(const Mat3& V, const Vec3& values) {
  Mat3 A{};
  for (int i = 0; i < 3; ++i)
    for (int j = i; j < 3; ++j) {
      for (int k = 0; k < 3; ++k)
        A[i][j] += V[i][k] * values[k] * V[j][k];
      A[j][i] = A[i][j];
    }
  return A;
}

double rotation_distance(const Mat3& A, const Mat3& B) {
  double f = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      f += (A[i][j] - B[i][j]) * (A[i][j] - B[i][j]);
  return 2 * std::asin(std::min(1.0, std::sqrt(f) / (2 * std::sqrt(2.0))));
}

}  // namespace arbor::gen
