// Proves the allocation guard fires for every allocation path, and stays quiet otherwise.
#include "alloc_guard.hpp"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdlib>
#include <memory>
#include <vector>

namespace {

// Keeps the optimizer from removing an allocation/free pair.
template <class T>
void escape(T* p) {
  asm volatile("" : : "g"(p) : "memory");
}

TEST(AllocGuard, QuietWithoutAllocation) {
  arbor::test::NoAllocScope guard;
  Eigen::Matrix<double, 6, 6> m = Eigen::Matrix<double, 6, 6>::Identity();
  m = m * m;
  escape(&m);
  EXPECT_EQ(guard.count(), 0u);
}

TEST(AllocGuard, FiresOnOperatorNew) {
  EXPECT_NONFATAL_FAILURE(
      {
        arbor::test::NoAllocScope guard;
        int* p = new int(3);
        escape(p);
        delete p;
      },
      "heap allocation");
}

TEST(AllocGuard, FiresOnMalloc) {
  EXPECT_NONFATAL_FAILURE(
      {
        arbor::test::NoAllocScope guard;
        void* p = std::malloc(64);
        escape(p);
        std::free(p);
      },
      "heap allocation");
}

TEST(AllocGuard, FiresOnStdContainers) {
  EXPECT_NONFATAL_FAILURE(
      {
        arbor::test::NoAllocScope guard;
        std::vector<double> v(100, 1.0);
        escape(v.data());
      },
      "heap allocation");
}

TEST(AllocGuard, FiresOnAlignedNew) {
  struct alignas(64) Big {
    double x[8];
  };
  EXPECT_NONFATAL_FAILURE(
      {
        arbor::test::NoAllocScope guard;
        auto p = std::make_unique<Big>();
        escape(p.get());
      },
      "heap allocation");
}

TEST(AllocGuard, CountsEachAllocation) {
  EXPECT_NONFATAL_FAILURE(
      {
        arbor::test::NoAllocScope guard;
        for (int i = 0; i < 3; ++i) {
          void* p = std::calloc(4, 4);
          escape(p);
          std::free(p);
        }
        EXPECT_EQ(guard.count(), 3u);
      },
      "3 heap allocation");
}

#ifdef EIGEN_RUNTIME_NO_MALLOC
TEST(AllocGuardDeathTest, EigenDynamicAllocationAborts) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_DEATH(
      {
        arbor::test::NoAllocScope guard;
        Eigen::MatrixXd m(50, 50);
        escape(m.data());
      },
      "");
}
#endif

}  // namespace
