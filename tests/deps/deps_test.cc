// One smoke test per third-party dependency: each proves the library is found, linked and does real work.
#include <cstdio>
#include <filesystem>

#include <Eigen/CholmodSupport>
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <omp.h>
#include <sqlite3.h>

TEST(Dependencies, EigenSolvesADenseSystem) {
  Eigen::Matrix3d A;
  A << 4, 1, 0, 1, 3, 1, 0, 1, 2;
  const Eigen::Vector3d x(1, -2, 3);
  EXPECT_LT((A.llt().solve(A * x) - x).norm(), 1e-14);
}

TEST(Dependencies, CholmodFactorisesASparseMatrix) {
  const int n = 50;
  Eigen::SparseMatrix<double> A(n, n);
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 4.0);
    if (i + 1 < n) {
      t.emplace_back(i, i + 1, -1.0);
      t.emplace_back(i + 1, i, -1.0);
    }
  }
  A.setFromTriplets(t.begin(), t.end());
  Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> chol;
  chol.compute(A);
  ASSERT_EQ(chol.info(), Eigen::Success);
  const Eigen::VectorXd x = Eigen::VectorXd::LinSpaced(n, -1.0, 1.0);
  EXPECT_LT((chol.solve(A * x) - x).norm(), 1e-13);
}

TEST(Dependencies, OpenMPRunsAParallelReduction) {
  long sum = 0;
#pragma omp parallel for reduction(+ : sum)
  for (int i = 1; i <= 1000; ++i) sum += i;
  EXPECT_EQ(sum, 500500);
  EXPECT_GE(omp_get_max_threads(), 1);
}

TEST(Dependencies, HDF5WritesAndReadsADataset) {
  std::filesystem::create_directories(CAPSIM_TEST_TMP);
  const std::string path = std::string(CAPSIM_TEST_TMP) + "/deps_smoke.h5";
  const double data[4] = {1.5, -2.0, 3.25, 4.0};
  hid_t f = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  hsize_t dims[1] = {4};
  hid_t space = H5Screate_simple(1, dims, nullptr);
  hid_t ds = H5Dcreate2(f, "x", H5T_NATIVE_DOUBLE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ASSERT_GE(H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0);
  H5Dclose(ds);
  H5Sclose(space);
  H5Fclose(f);
  double back[4] = {};
  f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  ds = H5Dopen2(f, "x", H5P_DEFAULT);
  ASSERT_GE(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, back), 0);
  H5Dclose(ds);
  H5Fclose(f);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(back[i], data[i]);
}

TEST(Dependencies, SQLiteRunsAQuery) {
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(":memory:", &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE t(x REAL); INSERT INTO t VALUES (1.5), (2.5);", nullptr, nullptr, nullptr),
            SQLITE_OK);
  sqlite3_stmt* st = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT SUM(x) FROM t", -1, &st, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(st), SQLITE_ROW);
  EXPECT_DOUBLE_EQ(sqlite3_column_double(st, 0), 4.0);
  sqlite3_finalize(st);
  sqlite3_close(db);
}
