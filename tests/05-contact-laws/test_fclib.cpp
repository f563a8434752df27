// Chapter 5: the FCLIB reader and the local problem ξ = W λ + q — reading the three FCLIB files of
// chapters/05-contact-laws/data, the three sparse storage kinds, the refusal of malformed files,
// the block-sparse Delassus matrix and the conversion of a global problem to local form.
//
// Independent references: the file contents as listed by a separate program on HDF5's own
// H5Ovisit/H5Dread (contact counts 60, 286, 356 also in the README; titles, storage kinds, first
// values); small matrices written by this test with the HDF5 C API in all three storage kinds and
// compared with the dense matrix written down by hand; W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w by a dense
// Cholesky factorization (Eigen::LLT) and dense products; y = W x by Eigen's sparse product;
// malformed files made by this test (deleted or rewritten datasets, truncated copies, text files).

#include <gtest/gtest.h>
#include <hdf5.h>

#include <sys/stat.h>
#include <unistd.h>
#include <Eigen/Dense>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <system_error>
#include <typeinfo>
#include <utility>
#include <vector>

#include "grbd/contact/fclib.hpp"
#include "grbd/contact/local_problem.hpp"
#include "grbd/core/checks.hpp"
#include "grbd/core/error.hpp"
#include "grbd_test/hdf5.hpp"
#include "grbd_test/random.hpp"
#include "grbd_test/temp_dir.hpp"
#include "grbd_test/watchdog.hpp"

namespace {

namespace fs = std::filesystem;
using grbd::Matrix3;
using grbd::Vector3;
using grbd::contact::BlockSparseMatrix;
using grbd::contact::FclibKind;
using grbd::contact::GlobalProblem;
using grbd::contact::LocalProblem;
using grbd::test::H5;
using grbd::test::TempDir;
using grbd::test::within;
using SparseMatrix = Eigen::SparseMatrix<double>;

constexpr const char* kPerioBox = "LMGC_100_PR_PerioBox-i00361-60-03000.hdf5";
constexpr const char* kCapsules = "Capsules-i125-1213.hdf5";
constexpr const char* kSpheres = "Spheres-i099-356-679.hdf5";

// ---------------------------------------------------------------------------------------------
// Helpers: data files, temporary folders, messages.

fs::path data_file(const char* name) { return fs::path(GRBD_FCLIB_DATA_DIR) / name; }

// A writable copy of the data file `name` in `dir`.
fs::path writable_copy(const TempDir& dir, const char* name) {
  const fs::path copy = dir / name;
  fs::copy_file(data_file(name), copy);
  fs::permissions(copy, fs::perms::owner_read | fs::perms::owner_write, fs::perm_options::add);
  return copy;
}

// The message of the exception of type E that `f` throws; a failure if it throws none or another.
template <class E = grbd::Error, class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const E& error) {
    return error.what();
  } catch (const std::exception& error) {
    ADD_FAILURE() << "expected the exception type " << typeid(E).name() << ", got "
                  << typeid(error).name() << ": " << error.what();
    return {};
  }
  ADD_FAILURE() << "expected an exception, none was thrown";
  return {};
}

// Whether `message` contains every one of `parts`.
::testing::AssertionResult contains(const std::string& message,
                                    std::initializer_list<std::string> parts) {
  for (const std::string& part : parts) {
    if (message.find(part) == std::string::npos) {
      return ::testing::AssertionFailure() << "\"" << message << "\" lacks \"" << part << "\"";
    }
  }
  return ::testing::AssertionSuccess();
}

// ---------------------------------------------------------------------------------------------
// Writing HDF5 with the C API.

// The number of HDF5 objects (files, groups, datasets, ...) open in the process.
ssize_t open_hdf5_objects() { return H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL); }

H5 create_file(const fs::path& path) {
  return H5(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
}
H5 open_file(const fs::path& path) {
  return H5(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
}

void make_group(hid_t file, const std::string& name) {
  const H5 group(H5Gcreate2(file, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose);
  ASSERT_GE(group.get(), 0) << name;
}

// A one-dimensional dataset `name` of `count` elements, stored as `file_type`, written from `data`
// of `memory_type`.
void write_dataset(hid_t file, const std::string& name, hid_t file_type, hid_t memory_type,
                   const void* data, hsize_t count) {
  const H5 space(H5Screate_simple(1, &count, nullptr), H5Sclose);
  const H5 dataset(
      H5Dcreate2(file, name.c_str(), file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
      H5Dclose);
  ASSERT_GE(dataset.get(), 0) << name;
  if (count > 0) {
    ASSERT_GE(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0) << name;
  }
}

void write_integers(hid_t file, const std::string& name, const std::vector<std::int64_t>& values,
                    hid_t file_type = H5T_STD_I32LE) {
  write_dataset(file, name, file_type, H5T_NATIVE_INT64, values.data(), values.size());
}

void write_reals(hid_t file, const std::string& name, const std::vector<double>& values) {
  write_dataset(file, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, values.data(), values.size());
}

// Replaces the dataset `name` of the file at `path`.
void replace_integers(const fs::path& path, const std::string& name,
                      const std::vector<std::int64_t>& values) {
  const H5 file = open_file(path);
  ASSERT_GE(file.get(), 0);
  ASSERT_GE(H5Ldelete(file.get(), name.c_str(), H5P_DEFAULT), 0) << name;
  write_integers(file.get(), name, values);
}
void replace_reals(const fs::path& path, const std::string& name,
                   const std::vector<double>& values) {
  const H5 file = open_file(path);
  ASSERT_GE(file.get(), 0);
  ASSERT_GE(H5Ldelete(file.get(), name.c_str(), H5P_DEFAULT), 0) << name;
  write_reals(file.get(), name, values);
}
void delete_object(const fs::path& path, const std::string& name) {
  const H5 file = open_file(path);
  ASSERT_GE(file.get(), 0);
  ASSERT_GE(H5Ldelete(file.get(), name.c_str(), H5P_DEFAULT), 0) << name;
}

// An FCLIB sparse matrix as stored: {m, n, nz, nzmax, p, i, x}.
struct StoredMatrix {
  std::int64_t m = 0, n = 0, nz = 0, nzmax = 0;
  std::vector<std::int64_t> p, i;
  std::vector<double> x;
  hid_t integer_type = H5T_STD_I32LE;
};

StoredMatrix stored(std::int64_t m, std::int64_t n, std::int64_t nz, std::int64_t nzmax,
                    std::vector<std::int64_t> p, std::vector<std::int64_t> i, std::vector<double> x,
                    hid_t integer_type = H5T_STD_I32LE) {
  return StoredMatrix{m, n, nz, nzmax, std::move(p), std::move(i), std::move(x), integer_type};
}

void write_matrix(hid_t file, const std::string& group, const StoredMatrix& A) {
  make_group(file, group);
  write_integers(file, group + "/m", {A.m}, A.integer_type);
  write_integers(file, group + "/n", {A.n}, A.integer_type);
  write_integers(file, group + "/nz", {A.nz}, A.integer_type);
  write_integers(file, group + "/nzmax", {A.nzmax}, A.integer_type);
  write_integers(file, group + "/p", A.p, A.integer_type);
  write_integers(file, group + "/i", A.i, A.integer_type);
  write_reals(file, group + "/x", A.x);
}

// A triplet copy of the sparse matrix A (nz = nzmax = its entries).
StoredMatrix triplets_of(const SparseMatrix& A) {
  StoredMatrix S;
  S.m = A.rows();
  S.n = A.cols();
  for (Eigen::Index c = 0; c < A.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(A, c); it; ++it) {
      S.i.push_back(it.row());
      S.p.push_back(it.col());
      S.x.push_back(it.value());
    }
  }
  S.nz = S.nzmax = static_cast<std::int64_t>(S.x.size());
  return S;
}

// Writes a local FCLIB problem (W as triplets, q, mu, spacedim) to a new file at `path`.
void write_local_file(const fs::path& path, const SparseMatrix& W, const std::vector<double>& q,
                      const std::vector<double>& mu, std::int64_t spacedim = 3) {
  const H5 file = create_file(path);
  ASSERT_GE(file.get(), 0) << path;
  make_group(file.get(), "/fclib_local");
  write_integers(file.get(), "/fclib_local/spacedim", {spacedim});
  write_matrix(file.get(), "/fclib_local/W", triplets_of(W));
  make_group(file.get(), "/fclib_local/vectors");
  write_reals(file.get(), "/fclib_local/vectors/q", q);
  write_reals(file.get(), "/fclib_local/vectors/mu", mu);
}

// ---------------------------------------------------------------------------------------------
// Dense references.

Eigen::MatrixXd dense(const BlockSparseMatrix& W) {
  const auto n = static_cast<Eigen::Index>(W.size());
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (auto k = W.row_start[static_cast<std::size_t>(i)];
         k < W.row_start[static_cast<std::size_t>(i) + 1]; ++k) {
      D.block<3, 3>(3 * i, 3 * W.column[static_cast<std::size_t>(k)]) +=
          W.blocks[static_cast<std::size_t>(k)];
    }
  }
  return D;
}

Eigen::VectorXd flat(const std::vector<Vector3>& v) {
  Eigen::VectorXd x(3 * static_cast<Eigen::Index>(v.size()));
  for (std::size_t i = 0; i < v.size(); ++i) x.segment<3>(3 * static_cast<Eigen::Index>(i)) = v[i];
  return x;
}

double max_abs(const Eigen::MatrixXd& A) { return A.size() == 0 ? 0.0 : A.cwiseAbs().maxCoeff(); }

// A random sparse symmetric matrix of n × n blocks of 3 × 3: a random block pattern with density
// `fill`, diagonal blocks SPD.
SparseMatrix random_symmetric_blocks(int n, double fill, grbd::test::Random& random) {
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < i; ++j) {
      if (random.uniform(0.0, 1.0) >= fill) continue;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) D(3 * i + r, 3 * j + c) = random.uniform();
      }
      D.block<3, 3>(3 * j, 3 * i) = D.block<3, 3>(3 * i, 3 * j).transpose();
    }
    Matrix3 A;
    for (int r = 0; r < 3; ++r) A.row(r) = random.vector3().transpose();
    D.block<3, 3>(3 * i, 3 * i) = A * A.transpose() + Matrix3::Identity();
  }
  return D.sparseView();
}

// A small valid local problem of 3 contacts with a coupled, symmetric W.
LocalProblem small_problem() {
  grbd::test::Random random(7);
  LocalProblem problem;
  problem.W = grbd::contact::to_block_sparse(random_symmetric_blocks(3, 1.0, random));
  problem.q = {random.vector3(), random.vector3(), random.vector3()};
  problem.mu = {0.3, 0.0, 0.8};
  return problem;
}

// ---------------------------------------------------------------------------------------------
// FclibReader: the three files of chapters/05-contact-laws/data.

TEST(FclibReader, InfoOfTheThreeFiles) {
  const auto perio = grbd::contact::read_fclib_info(data_file(kPerioBox));
  EXPECT_EQ(perio.kind, FclibKind::local);
  EXPECT_EQ(perio.contacts, 60);
  EXPECT_EQ(perio.title, "LMGC dump in hdf5");
  EXPECT_EQ(perio.math_info, "unknown");
  EXPECT_TRUE(contains(perio.description, {"LMGC_FC3D-i00361-60-03000.hdf5"}));
  EXPECT_FALSE(perio.guess.has_value());

  const auto capsules = grbd::contact::read_fclib_info(data_file(kCapsules));
  EXPECT_EQ(capsules.kind, FclibKind::local);
  EXPECT_EQ(capsules.contacts, 286);
  EXPECT_EQ(capsules.title, "Capsules");
  EXPECT_EQ(capsules.math_info, "");
  EXPECT_TRUE(contains(capsules.description, {"Capsules falling on the ground", "F3D_NSGS"}));
  ASSERT_TRUE(capsules.guess.has_value());
  ASSERT_EQ(capsules.guess->size(), 286U);
  EXPECT_NEAR((*capsules.guess)[0].x(), 0.00290366, 1e-8);  // /guesses/1/r[0]
  EXPECT_NEAR((*capsules.guess)[0].y(), -0.000823767, 1e-9);

  const auto spheres = grbd::contact::read_fclib_info(data_file(kSpheres));
  EXPECT_EQ(spheres.kind, FclibKind::global);
  EXPECT_EQ(spheres.contacts, 356);
  EXPECT_EQ(spheres.title, "Spheres Tower");
  EXPECT_TRUE(contains(spheres.description, {"GFC3D_NSGS_WR"}));
  ASSERT_TRUE(spheres.guess.has_value());
  EXPECT_EQ(spheres.guess->size(), 356U);
}

TEST(FclibReader, LocalFilesReadConsistently) {
  struct Case {
    const char* file;
    std::size_t contacts;
    double W00;  // W(0, 0), the first x of the compressed rows
    double q0;   // q[0]
    double mu_min, mu_max;
  };
  for (const Case& c : {Case{kPerioBox, 60, 1.02313e-05, -0.196194, 0.3, 0.5},
                        Case{kCapsules, 286, 1.89608, -0.004905, 0.7, 0.7}}) {
    SCOPED_TRACE(c.file);
    const LocalProblem problem = grbd::contact::read_fclib_local(data_file(c.file));
    ASSERT_EQ(problem.W.size(), c.contacts);
    ASSERT_EQ(problem.q.size(), c.contacts);
    ASSERT_EQ(problem.mu.size(), c.contacts);
    EXPECT_NEAR(problem.W.blocks[static_cast<std::size_t>(problem.W.diagonal[0])](0, 0), c.W00,
                1e-5 * std::abs(c.W00));
    EXPECT_NEAR(problem.q[0].x(), c.q0, 1e-5 * std::abs(c.q0));
    EXPECT_EQ(*std::min_element(problem.mu.begin(), problem.mu.end()), c.mu_min);
    EXPECT_EQ(*std::max_element(problem.mu.begin(), problem.mu.end()), c.mu_max);

    // The scalar W read on its own is the same matrix as the blocks, with a positive diagonal.
    const SparseMatrix W = grbd::contact::read_fclib_matrix(data_file(c.file), "/fclib_local/W");
    ASSERT_EQ(W.rows(), static_cast<Eigen::Index>(3 * c.contacts));
    const Eigen::MatrixXd Wd(W);
    EXPECT_EQ(max_abs(dense(problem.W) - Wd), 0.0);
    EXPECT_GT(Wd.diagonal().minCoeff(), 0.0);

    // read_fclib_as_local of a local file is read_fclib_local.
    const LocalProblem again = grbd::contact::read_fclib_as_local(data_file(c.file));
    EXPECT_EQ(again.W.column, problem.W.column);
    EXPECT_EQ(max_abs(dense(again.W) - Wd), 0.0);
    EXPECT_EQ(flat(again.q), flat(problem.q));
    EXPECT_EQ(again.mu, problem.mu);
  }
}

// W of PerioBox (LMGC90) is symmetric to rounding (max |W − Wᵀ| ≈ 1.5e-16 max |W|). W of Capsules
// (Siconos, Newton–Euler bodies whose iteration matrix holds the non-symmetric gyroscopic
// Jacobian) is not: ‖W − Wᵀ‖_F / ‖W‖_F ≈ 3.4e-4, max |W − Wᵀ| ≈ 1.3e-3 max |W|, about 2 % of the
// entries within block (268, 268). The reader passes both on unchanged and validate() accepts both:
// symmetry is not part of its contract.
TEST(FclibReader, SymmetryOfTheLocalFiles) {
  const Eigen::MatrixXd perio(
      grbd::contact::read_fclib_matrix(data_file(kPerioBox), "/fclib_local/W"));
  EXPECT_LE(max_abs(perio - perio.transpose()), 1e-14 * max_abs(perio));
  EXPECT_NO_THROW(grbd::contact::validate(grbd::contact::read_fclib_local(data_file(kPerioBox))));

  const Eigen::MatrixXd capsules(
      grbd::contact::read_fclib_matrix(data_file(kCapsules), "/fclib_local/W"));
  const double asymmetry = (capsules - capsules.transpose()).norm() / capsules.norm();
  EXPECT_GT(asymmetry, 1e-4);
  EXPECT_LT(asymmetry, 1e-3);
  EXPECT_GT(max_abs(capsules - capsules.transpose()), 1e-3 * max_abs(capsules));
  const Eigen::Matrix3d B = capsules.block<3, 3>(3 * 268, 3 * 268);
  EXPECT_NEAR(B(1, 2), 0.392163, 1e-6);
  EXPECT_NEAR(B(2, 1), 0.401612, 1e-6);
  const LocalProblem problem = grbd::contact::read_fclib_local(data_file(kCapsules));
  EXPECT_EQ(max_abs(dense(problem.W) - capsules), 0.0);  // not symmetrized by the reader
  EXPECT_NO_THROW(grbd::contact::validate(problem));
}

TEST(FclibReader, GlobalFileSizes) {
  const GlobalProblem g = grbd::contact::read_fclib_global(data_file(kSpheres));
  EXPECT_EQ(g.M.rows(), 12000);
  EXPECT_EQ(g.M.cols(), 12000);
  EXPECT_EQ(g.H.rows(), 12000);
  EXPECT_EQ(g.H.cols(), 3 * 356);
  EXPECT_EQ(g.f.size(), 12000);
  EXPECT_EQ(g.w.size(), 3 * 356);
  EXPECT_EQ(g.mu.size(), 356U);
  // M is diagonal (12000 triplets on the diagonal), masses and inertias in [0.196, 1].
  EXPECT_EQ(g.M.nonZeros(), 12000);
  const Eigen::VectorXd diagonal = g.M.diagonal();
  EXPECT_NEAR(diagonal.minCoeff(), 0.196, 1e-8);  // 0.196 rounded to single precision
  EXPECT_EQ(diagonal.maxCoeff(), 1.0);
  EXPECT_LE(g.H.nonZeros(), 9110);  // 9110 triplets, duplicates summed
  EXPECT_NEAR(g.f[0], -0.337196, 1e-6);
  EXPECT_EQ(g.w.cwiseAbs().maxCoeff(), 0.0);
  // The local reader refuses the global file, naming what it found.
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_local(data_file(kSpheres)); }),
                       {data_file(kSpheres).string(), "global problem", "/fclib_local"}));
}

// W = Hᵀ M⁻¹ H and q = Hᵀ M⁻¹ f + w against dense Cholesky. Only the S degrees of freedom that H
// touches enter, provided M couples none of them to the others (checked): then
// Hᵀ M⁻¹ H = H_Sᵀ M_SS⁻¹ H_S and Hᵀ M⁻¹ f = H_Sᵀ M_SS⁻¹ f_S exactly.
TEST(FclibReader, ToLocalOfSpheresMatchesDenseCholesky) {
  const GlobalProblem g = grbd::contact::read_fclib_global(data_file(kSpheres));
  std::vector<int> S;
  {
    std::set<int> rows;
    for (Eigen::Index c = 0; c < g.H.outerSize(); ++c) {
      for (SparseMatrix::InnerIterator it(g.H, c); it; ++it)
        rows.insert(static_cast<int>(it.row()));
    }
    S.assign(rows.begin(), rows.end());
  }
  std::vector<int> position(static_cast<std::size_t>(g.M.rows()), -1);
  for (std::size_t k = 0; k < S.size(); ++k)
    position[static_cast<std::size_t>(S[k])] = static_cast<int>(k);
  const auto s = static_cast<Eigen::Index>(S.size());
  ASSERT_GT(s, 0);
  ASSERT_LT(s, 5000);  // the dense reference stays affordable
  Eigen::MatrixXd M_SS = Eigen::MatrixXd::Zero(s, s);
  for (Eigen::Index c = 0; c < g.M.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(g.M, c); it; ++it) {
      const int a = position[static_cast<std::size_t>(it.row())];
      const int b = position[static_cast<std::size_t>(it.col())];
      ASSERT_EQ(a < 0, b < 0) << "M couples a contact degree of freedom to another";
      if (a >= 0) M_SS(a, b) = it.value();
    }
  }
  Eigen::MatrixXd H_S = Eigen::MatrixXd::Zero(s, g.H.cols());
  for (Eigen::Index c = 0; c < g.H.outerSize(); ++c) {
    for (SparseMatrix::InnerIterator it(g.H, c); it; ++it) {
      H_S(position[static_cast<std::size_t>(it.row())], it.col()) += it.value();
    }
  }
  Eigen::VectorXd f_S(s);
  for (Eigen::Index k = 0; k < s; ++k) f_S[k] = g.f[S[static_cast<std::size_t>(k)]];

  const Eigen::LLT<Eigen::MatrixXd> llt(M_SS);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::MatrixXd W_ref = H_S.transpose() * llt.solve(H_S);
  const Eigen::VectorXd q_ref = H_S.transpose() * llt.solve(f_S) + g.w;

  const LocalProblem local = grbd::contact::to_local(g);
  ASSERT_EQ(local.W.size(), 356U);
  EXPECT_LE(max_abs(dense(local.W) - W_ref), 1e-12 * max_abs(W_ref));
  EXPECT_LE(max_abs(flat(local.q) - q_ref), 1e-12 * max_abs(q_ref));
  EXPECT_EQ(local.mu, g.mu);
  EXPECT_NO_THROW(grbd::contact::validate(local));

  // read_fclib_as_local converts the same way.
  const LocalProblem as_local = grbd::contact::read_fclib_as_local(data_file(kSpheres));
  EXPECT_EQ(max_abs(dense(as_local.W) - dense(local.W)), 0.0);
  EXPECT_EQ(flat(as_local.q), flat(local.q));
}

// ---------------------------------------------------------------------------------------------
// FclibReader: malformed files.

TEST(FclibReader, MissingDatasetsAreNamed) {
  TempDir dir;
  struct Case {
    const char* object;
    const char* expected;
  };
  for (const Case& c : {Case{"/fclib_local/vectors/q", "dataset /fclib_local/vectors/q is missing"},
                        Case{"/fclib_local/W/p", "dataset /fclib_local/W/p is missing"},
                        Case{"/fclib_local/W/x", "dataset /fclib_local/W/x is missing"},
                        Case{"/fclib_local/W/nz", "dataset /fclib_local/W/nz is missing"},
                        Case{"/fclib_local/spacedim", "dataset /fclib_local/spacedim is missing"},
                        Case{"/fclib_local/vectors", "group /fclib_local/vectors is missing"},
                        Case{"/fclib_local/W", "group /fclib_local/W is missing"}}) {
    SCOPED_TRACE(c.object);
    const fs::path copy = dir / (std::string("missing-") +
                                 std::to_string(std::hash<std::string>{}(c.object)) + ".hdf5");
    fs::copy_file(data_file(kPerioBox), copy);
    fs::permissions(copy, fs::perms::owner_write, fs::perm_options::add);
    delete_object(copy, c.object);
    const std::string message = error_message([&] { grbd::contact::read_fclib_local(copy); });
    EXPECT_EQ(message.rfind(copy.string() + ": ", 0), 0U) << message;
    EXPECT_TRUE(contains(message, {c.expected}));
  }
  // The global reader names its datasets too.
  const fs::path global = writable_copy(dir, kSpheres);
  delete_object(global, "/fclib_global/vectors/f");
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_global(global); }),
                       {global.string(), "dataset /fclib_global/vectors/f is missing"}));
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_as_local(global); }),
                       {global.string(), "dataset /fclib_global/vectors/f is missing"}));
}

TEST(FclibReader, TruncatedAndForeignFilesAreRefusedByName) {
  TempDir dir;
  for (const char* name : {kPerioBox, kSpheres}) {
    SCOPED_TRACE(name);
    const fs::path truncated = dir / (std::string("truncated-") + name);
    {
      std::ifstream in(data_file(name), std::ios::binary);
      const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
      ASSERT_GT(bytes.size(), 1000U);
      std::ofstream out(truncated, std::ios::binary);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
    }
    for (const auto& read : std::vector<std::function<void()>>{
             [&] { grbd::contact::read_fclib_info(truncated); },
             [&] { grbd::contact::read_fclib_as_local(truncated); },
             [&] { grbd::contact::read_fclib_matrix(truncated, "/fclib_local/W"); }}) {
      ::testing::internal::CaptureStderr();
      const std::string message = error_message(read);
      EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << "HDF5 printed its error stack";
      EXPECT_EQ(message.rfind(truncated.string() + ": ", 0), 0U) << message;
      EXPECT_TRUE(contains(message, {"truncated"}));
    }
  }
  // HDF5's automatic error printing, switched off while the reader runs, is on again.
  H5E_auto2_t handler = nullptr;
  void* handler_data = nullptr;
  H5Eget_auto2(H5E_DEFAULT, &handler, &handler_data);
  EXPECT_NE(handler, nullptr);

  const fs::path text = dir / "problem.hdf5";
  std::ofstream(text) << "This is not an HDF5 file.\n1 2 3\n";
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_local(text); }),
                       {text.string() + ": ", "not an HDF5 file"}));
  const fs::path empty = dir / "empty.hdf5";
  std::ofstream(empty).flush();
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_global(empty); }),
                       {empty.string() + ": "}));
  const fs::path absent = dir / "absent.hdf5";
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_info(absent); }),
                       {absent.string() + ": ", "no such file"}));
  // An HDF5 file without FCLIB groups.
  const fs::path other = dir / "other.hdf5";
  {
    const H5 file = create_file(other);
    make_group(file.get(), "/something");
  }
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_info(other); }),
                       {other.string() + ": ", "/fclib_local", "/fclib_global"}));
  EXPECT_EQ(open_hdf5_objects(), 0) << "a refused file left HDF5 objects open";
}

TEST(FclibReader, MalformedDatasetsAreRefusedByName) {
  TempDir dir;
  int count = 0;
  const auto copy = [&](const char* name) {
    const fs::path path = dir / (std::to_string(count++) + "-" + name);
    fs::copy_file(data_file(name), path);
    fs::permissions(path, fs::perms::owner_write, fs::perm_options::add);
    return path;
  };
  const auto local_error = [](const fs::path& path) {
    return error_message([&] { grbd::contact::read_fclib_local(path); });
  };

  {  // 2D problems are refused, by the info reader as well.
    const fs::path path = copy(kPerioBox);
    replace_integers(path, "/fclib_local/spacedim", {2});
    EXPECT_TRUE(contains(local_error(path), {path.string(), "/fclib_local/spacedim is 2", "3"}));
    EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_info(path); }),
                         {"/fclib_local/spacedim is 2"}));
  }
  {  // q one entry short.
    const fs::path path = copy(kPerioBox);
    std::vector<double> q(179, 0.5);
    replace_reals(path, "/fclib_local/vectors/q", q);
    EXPECT_TRUE(
        contains(local_error(path), {path.string(), "/fclib_local/vectors/q has 179 entries",
                                     "3n = 180", "/fclib_local/vectors/mu"}));
  }
  {  // mu one entry longer: n comes from W (180 × 180 = 3n × 3n), and mu must have n entries.
    const fs::path path = copy(kPerioBox);
    replace_reals(path, "/fclib_local/vectors/mu", std::vector<double>(61, 0.5));
    EXPECT_TRUE(contains(local_error(path), {"/fclib_local/vectors/mu has 61 entries", "n = 60",
                                             "/fclib_local/W is 180 × 180"}));
  }
  {  // A negative friction coefficient, a NaN in q.
    const fs::path path = copy(kPerioBox);
    std::vector<double> mu(60, 0.5);
    mu[7] = -0.25;
    replace_reals(path, "/fclib_local/vectors/mu", mu);
    EXPECT_TRUE(contains(local_error(path), {"/fclib_local/vectors/mu entry 7 is -0.25"}));
    std::vector<double> q(180, 0.5);
    q[11] = std::numeric_limits<double>::quiet_NaN();
    replace_reals(path, "/fclib_local/vectors/mu", std::vector<double>(60, 0.5));
    replace_reals(path, "/fclib_local/vectors/q", q);
    EXPECT_TRUE(contains(local_error(path), {"/fclib_local/vectors/q entry 11 is nan"}));
  }
  {  // p of the compressed rows not monotone, then of the wrong length.
    const fs::path path = copy(kPerioBox);
    std::vector<std::int64_t> p(181);
    for (int k = 0; k <= 180; ++k) p[static_cast<std::size_t>(k)] = k * 9576 / 180;
    std::swap(p[4], p[5]);
    replace_integers(path, "/fclib_local/W/p", p);
    EXPECT_TRUE(contains(local_error(path), {"/fclib_local/W/p is not monotone", "p[4]"}));
    p.pop_back();
    replace_integers(path, "/fclib_local/W/p", p);
    EXPECT_TRUE(contains(local_error(path),
                         {"/fclib_local/W/p has 180 entries", "m + 1 = 181", "compressed rows"}));
  }
  {  // A column index out of range in the compressed rows; x shorter than p[m].
    const fs::path path = copy(kPerioBox);
    std::vector<std::int64_t> i(9576, 0);
    i[100] = 180;
    replace_integers(path, "/fclib_local/W/i", i);
    EXPECT_TRUE(contains(local_error(path),
                         {"/fclib_local/W/i: column index 180 (entry 100) out of range [0, 180)"}));
    replace_reals(path, "/fclib_local/W/x", std::vector<double>(9000, 1.0));
    replace_integers(path, "/fclib_local/W/i", std::vector<std::int64_t>(9576, 0));
    EXPECT_TRUE(
        contains(local_error(path), {"/fclib_local/W/x has 9000 entries", "at least p[m] = 9576"}));
  }
  {  // W of the wrong shape; an integer header stored as floating point.
    const fs::path path = copy(kPerioBox);
    replace_integers(path, "/fclib_local/W/m", {177});
    EXPECT_TRUE(
        contains(local_error(path), {"matrix /fclib_local/W is 177 × 180", "square 3n × 3n"}));
    replace_reals(path, "/fclib_local/W/m", {180.0});
    EXPECT_TRUE(contains(local_error(path),
                         {"/fclib_local/W/m holds floating-point data", "expected integer data"}));
  }
  {  // Equality constraints are refused.
    const fs::path path = copy(kPerioBox);
    {
      const H5 file = open_file(path);
      make_group(file.get(), "/fclib_local/R");
    }
    EXPECT_TRUE(contains(local_error(path), {"equality constraints", "/fclib_local/R"}));
  }
  {  // A global problem with G: refused if G is not empty, read if it is.
    const fs::path path = copy(kSpheres);
    {
      const H5 file = open_file(path);
      write_matrix(file.get(), "/fclib_global/G",
                   stored(12000, 2, 2, 2, {0, 1}, {5, 7}, {1.0, 1.0}, H5T_STD_I32LE));
    }
    EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_global(path); }),
                         {path.string(), "equality constraints", "/fclib_global/G is 12000 × 2"}));
    delete_object(path, "/fclib_global/G");
    {
      const H5 file = open_file(path);
      write_matrix(file.get(), "/fclib_global/G",
                   stored(12000, 0, 0, 0, {}, {}, {}, H5T_STD_I32LE));
    }
    EXPECT_EQ(grbd::contact::read_fclib_global(path).mu.size(), 356U);
  }
  {  // The triplets of H: a row index out of range; f of the wrong length.
    const fs::path path = copy(kSpheres);
    std::vector<std::int64_t> i(9110, 3);
    i[37] = 12000;
    replace_integers(path, "/fclib_global/H/i", i);
    EXPECT_TRUE(
        contains(error_message([&] { grbd::contact::read_fclib_global(path); }),
                 {"/fclib_global/H/i: row index 12000 (entry 37) out of range [0, 12000)"}));
    replace_reals(path, "/fclib_global/vectors/f", std::vector<double>(11999, 0.0));
    EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_global(path); }),
                         {"/fclib_global/vectors/f has 11999 entries", "m = 12000"}));
  }
  {  // A guess of the wrong size.
    const fs::path path = copy(kCapsules);
    replace_reals(path, "/guesses/1/r", std::vector<double>(10, 0.0));
    EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_info(path); }),
                         {path.string(), "/guesses/1/r has 10 entries", "3n = 858"}));
  }
  EXPECT_EQ(open_hdf5_objects(), 0) << "a refused file left HDF5 objects open";
}

// ---------------------------------------------------------------------------------------------
// FclibMatrix: the three storage kinds and malformed matrices, written by this test.

// The 4 × 3 matrix
//   [ 1  0  2 ]
//   [ 0  0  3 ]
//   [ 4  5  0 ]
//   [ 0 -6  7 ]
Eigen::MatrixXd known_matrix() {
  Eigen::MatrixXd A(4, 3);
  A << 1, 0, 2, 0, 0, 3, 4, 5, 0, 0, -6, 7;
  return A;
}

TEST(FclibMatrix, ThreeStorageKindsGiveTheSameMatrix) {
  TempDir dir;
  const fs::path path = dir / "kinds.hdf5";
  {
    const H5 file = create_file(path);
    ASSERT_GE(file.get(), 0);
    // Compressed columns, nzmax larger than p[n], junk (out of range) after p[n].
    write_matrix(file.get(), "/csc",
                 stored(4, 3, -1, 9, {0, 2, 4, 7}, {0, 2, 2, 3, 0, 1, 3, 99, -5},
                        {1, 4, 5, -6, 2, 3, 7, 1e300, -1e300}, H5T_STD_I32LE));
    // Compressed rows, 64-bit integers.
    write_matrix(file.get(), "/csr",
                 stored(4, 3, -2, 7, {0, 2, 3, 5, 7}, {0, 2, 2, 0, 1, 1, 2}, {1, 2, 3, 4, 5, -6, 7},
                        H5T_STD_I64LE));
    // Triplets (i = row, p = column) in no order, A(3, 2) = 7 split into the duplicates 3 + 4,
    // nzmax > nz, out-of-range junk after the nz entries, unsigned 8-bit integers.
    write_matrix(
        file.get(), "/triplets",
        stored(4, 3, 8, 12, {2, 0, 2, 2, 1, 2, 1, 0, 200, 200}, {3, 0, 3, 1, 2, 0, 3, 2, 200, 200},
               {3, 1, 4, 3, 5, 2, -6, 4, 1, 1}, H5T_STD_U8LE));
  }
  const Eigen::MatrixXd A = known_matrix();
  EXPECT_EQ(Eigen::MatrixXd(grbd::contact::read_fclib_matrix(path, "/csc")), A);
  EXPECT_EQ(Eigen::MatrixXd(grbd::contact::read_fclib_matrix(path, "//csr/")), A);
  const SparseMatrix T = grbd::contact::read_fclib_matrix(path, "/triplets");
  EXPECT_EQ(Eigen::MatrixXd(T), A);
  EXPECT_EQ(T.nonZeros(), 7);  // the duplicates were summed into one entry
}

TEST(FclibMatrix, MalformedMatricesAreRefusedByName) {
  TempDir dir;
  const fs::path path = dir / "malformed.hdf5";
  {
    const H5 file = create_file(path);
    ASSERT_GE(file.get(), 0);
    write_matrix(file.get(), "/row", stored(30, 30, 2, 2, {0, 1}, {5, 37}, {1, 2}));
    write_matrix(file.get(), "/column", stored(30, 30, 2, 2, {0, 30}, {5, 6}, {1, 2}));
    write_matrix(file.get(), "/short",
                 stored(30, 30, 12, 12, std::vector<std::int64_t>(12, 1),
                        std::vector<std::int64_t>(12, 1), std::vector<double>(10, 1.0)));
    write_matrix(file.get(), "/start", stored(2, 2, -1, 2, {1, 1, 2}, {0, 1}, {1, 2}));
    write_matrix(file.get(), "/csc_row", stored(2, 2, -1, 2, {0, 1, 2}, {0, 2}, {1, 2}));
    write_matrix(file.get(), "/kind", stored(2, 2, -3, 2, {0, 1}, {0, 1}, {1, 2}));
    write_matrix(file.get(), "/rows", stored(-1, 2, 0, 0, {}, {}, {}));
    write_matrix(file.get(), "/two", stored(2, 2, 0, 0, {}, {}, {}));
    ASSERT_GE(H5Ldelete(file.get(), "/two/n", H5P_DEFAULT), 0);
    write_integers(file.get(), "/two/n", {2, 2});
    write_matrix(file.get(), "/nan",
                 stored(2, 2, 2, 2, {0, 1}, {0, 1}, {1, std::numeric_limits<double>::quiet_NaN()}));
  }
  const auto message = [&](const std::string& group) {
    return error_message([&] { grbd::contact::read_fclib_matrix(path, group); });
  };
  const std::string file = path.string() + ": ";
  EXPECT_TRUE(contains(message("/row"),
                       {file, "dataset /row/i: row index 37 (entry 1) out of range [0, 30)"}));
  EXPECT_TRUE(
      contains(message("/column"),
               {file, "dataset /column/p: column index 30 (entry 1) out of range [0, 30)"}));
  EXPECT_TRUE(contains(message("/short"),
                       {file, "dataset /short/x has 10 entries, expected at least nz = 12"}));
  EXPECT_TRUE(contains(message("/start"), {file, "dataset /start/p starts with 1, expected 0"}));
  EXPECT_TRUE(contains(message("/csc_row"), {file, "/csc_row/i: row index 2 (entry 1)"}));
  EXPECT_TRUE(contains(message("/kind"), {file, "dataset /kind/nz is -3"}));
  EXPECT_TRUE(contains(message("/rows"), {file, "dataset /rows/m is -1"}));
  EXPECT_TRUE(
      contains(message("/two"), {file, "dataset /two/n has 2 entries, expected a single integer"}));
  EXPECT_TRUE(contains(message("/nan"), {file, "dataset /nan/x entry 1 is nan"}));
  EXPECT_TRUE(contains(message("/absent"), {file, "group /absent is missing"}));
  EXPECT_TRUE(contains(message("/row/x"), {file, "/row/x is a dataset, expected a group"}));
  EXPECT_TRUE(contains(
      error_message<grbd::InvalidArgument>([&] { grbd::contact::read_fclib_matrix(path, ""); }),
      {"read_fclib_matrix"}));
  EXPECT_EQ(open_hdf5_objects(), 0) << "a refused matrix left HDF5 objects open";
}

// A local problem written by this test (W as triplets) reads back exactly; spacedim 2 is refused.
TEST(FclibReader, ReadsALocalProblemWrittenByTheTest) {
  TempDir dir;
  grbd::test::Random random(11);
  const SparseMatrix W = random_symmetric_blocks(5, 0.4, random);
  std::vector<double> q(15), mu(5);
  for (double& v : q) v = random.uniform();
  for (double& v : mu) v = random.uniform(0.0, 1.0);
  const fs::path path = dir / "local.hdf5";
  write_local_file(path, W, q, mu);
  const LocalProblem problem = grbd::contact::read_fclib_local(path);
  EXPECT_EQ(dense(problem.W), Eigen::MatrixXd(W));
  EXPECT_EQ(flat(problem.q), Eigen::Map<const Eigen::VectorXd>(q.data(), 15));
  EXPECT_EQ(problem.mu, mu);
  EXPECT_NO_THROW(grbd::contact::validate(problem));
  const auto info = grbd::contact::read_fclib_info(path);
  EXPECT_EQ(info.kind, FclibKind::local);
  EXPECT_EQ(info.contacts, 5);
  EXPECT_EQ(info.title, "");
  EXPECT_FALSE(info.guess.has_value());

  const fs::path flat_path = dir / "2d.hdf5";
  write_local_file(flat_path, W, q, mu, 2);
  EXPECT_TRUE(contains(error_message([&] { grbd::contact::read_fclib_local(flat_path); }),
                       {flat_path.string() + ": ", "/fclib_local/spacedim is 2", "3D"}));
}

// ---------------------------------------------------------------------------------------------
// FclibReader: hostile files (issue 11, /work/shared/data/bad-inputs/README.md). Each case is
// built here with the HDF5 C API; each must be refused with a grbd::Error naming the file and the
// dataset, at once (well under a second), and never block.

// The message of the grbd::Error that `read` throws (a failure if none or another), which must
// come within `limit` seconds; the reader runs under a watchdog of 20 s.
template <class E = grbd::Error>
std::string prompt_refusal(const std::string& what, const std::function<void()>& read,
                           double limit = 1.0) {
  const auto start = std::chrono::steady_clock::now();
  const std::string message =
      error_message<E>([&] { within(std::chrono::seconds(20), what, read); });
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(seconds, limit) << what << " took " << seconds << " s to be refused";
  return message;
}

// Each reader that opens `/fclib_local/vectors/mu` or the whole file, as a list of (name, call).
std::vector<std::pair<std::string, std::function<void()>>> all_readers(const fs::path& path) {
  return {{"read_fclib_info", [path] { grbd::contact::read_fclib_info(path); }},
          {"read_fclib_local", [path] { grbd::contact::read_fclib_local(path); }},
          {"read_fclib_as_local", [path] { grbd::contact::read_fclib_as_local(path); }}};
}

// A valid local problem of 2 contacts with W stored as triplets.
void write_two_contacts(const fs::path& path) {
  Eigen::MatrixXd W = 2.0 * Eigen::MatrixXd::Identity(6, 6);
  W(0, 3) = W(3, 0) = 0.5;
  write_local_file(path, W.sparseView(), {-1, 0.1, 0, -0.5, 0, 0.2}, {0.3, 0.6});
}

// Replaces dataset `name` of the file at `path` by one of `count` entries (a scalar if count is
// 0 and `scalar`) of type `type`, made with the creation property list `dcpl`, into which nothing
// is written: its size is declared, not stored.
void replace_with_declared(const fs::path& path, const std::string& name, hid_t type, hsize_t count,
                           hid_t dcpl = H5P_DEFAULT, bool scalar = false) {
  const H5 file = open_file(path);
  ASSERT_GE(file.get(), 0);
  if (H5Lexists(file.get(), name.c_str(), H5P_DEFAULT) > 0) {
    ASSERT_GE(H5Ldelete(file.get(), name.c_str(), H5P_DEFAULT), 0) << name;
  }
  const hsize_t unlimited = H5S_UNLIMITED;
  const H5 space(scalar ? H5Screate(H5S_SCALAR)
                        : H5Screate_simple(1, &count, dcpl == H5P_DEFAULT ? nullptr : &unlimited),
                 H5Sclose);
  const H5 dataset(
      H5Dcreate2(file.get(), name.c_str(), type, space.get(), H5P_DEFAULT, dcpl, H5P_DEFAULT),
      H5Dclose);
  ASSERT_GE(dataset.get(), 0) << name;
}

// A creation property list for chunks of `chunk` entries, compressed with deflate if `deflate`.
H5 chunked(hsize_t chunk, bool deflate = false) {
  H5 dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  EXPECT_GE(H5Pset_chunk(dcpl.get(), 1, &chunk), 0);
  if (deflate) {
    EXPECT_GE(H5Pset_deflate(dcpl.get(), 6), 0);
  }
  return dcpl;
}

TEST(FclibReader, AFifoIsRefusedWithoutBlocking) {
  // Issue 11: a FIFO given as the file name blocked the reader forever (H5Fis_hdf5 opens it and
  // waits for a writer). Refused by its file type before HDF5 sees it.
  TempDir dir;
  const fs::path fifo = dir / "problem.hdf5";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path link = dir / "link.hdf5";
  fs::create_symlink(fifo, link);
  for (const fs::path& path : {fifo, link}) {
    auto readers = all_readers(path);
    readers.emplace_back("read_fclib_matrix",
                         [path] { grbd::contact::read_fclib_matrix(path, "/fclib_local/W"); });
    readers.emplace_back("read_fclib_global", [path] { grbd::contact::read_fclib_global(path); });
    for (const auto& [name, read] : readers) {
      SCOPED_TRACE(name + " of " + path.string());
      EXPECT_TRUE(contains(prompt_refusal(name + " of a FIFO", read),
                           {path.string() + ": ", "is a FIFO", "not a regular file"}));
    }
  }
}

TEST(FclibReader, ExistingButUnreadablePathsAreNotCalledMissing) {
  // Issue 11: every path that could not be examined was "no such file", its error code ignored.
  TempDir dir;
  const auto refusal = [](const fs::path& path) {
    return prompt_refusal("read_fclib_info of " + path.string(),
                          [path] { grbd::contact::read_fclib_info(path); });
  };
  const fs::path absent = dir / "absent.hdf5";
  EXPECT_TRUE(contains(refusal(absent), {absent.string() + ": ", "no such file"}));
  const fs::path folder = dir / "folder.hdf5";
  fs::create_directory(folder);
  EXPECT_TRUE(contains(refusal(folder), {folder.string() + ": ", "is a directory"}));
  // A symbolic link to itself exists but cannot be resolved (ELOOP).
  const fs::path loop = dir / "loop.hdf5";
  fs::create_symlink(loop, loop);
  const std::string loop_message = refusal(loop);
  EXPECT_TRUE(contains(loop_message, {loop.string() + ": ", "cannot be accessed",
                                      std::generic_category().message(ELOOP)}));
  EXPECT_EQ(loop_message.find("no such file"), std::string::npos) << loop_message;
  // A file without read permission (not testable as root, who reads it anyway).
  const fs::path locked = dir / "locked.hdf5";
  write_two_contacts(locked);
  fs::permissions(locked, fs::perms::none);
  if (::access(locked.c_str(), R_OK) != 0) {
    EXPECT_TRUE(contains(refusal(locked), {locked.string() + ": ", "cannot be opened",
                                           std::generic_category().message(EACCES)}));
  }
  fs::permissions(locked, fs::perms::owner_read | fs::perms::owner_write);
  EXPECT_EQ(grbd::contact::read_fclib_local(locked).mu.size(), 2U);
}

TEST(FclibReader, LinksOutOfTheFileAreNotFollowed) {
  // Issue 11: /fclib_local/vectors/mu as an external link to a FIFO blocked the reader forever
  // (HDF5 follows the link and opens the FIFO). No soft or external link is followed, and no
  // dataset whose data lie in another file (external storage, virtual dataset) is read.
  TempDir dir;
  const fs::path fifo = dir / "pipe";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const fs::path valid = dir / "valid.hdf5";
  write_two_contacts(valid);
  ASSERT_EQ(grbd::contact::read_fclib_local(valid).mu.size(), 2U);
  int count = 0;
  const auto variant = [&](const std::function<void(hid_t)>& edit) {
    const fs::path path = dir / ("variant-" + std::to_string(count++) + ".hdf5");
    fs::copy_file(valid, path);
    const H5 file = open_file(path);
    EXPECT_GE(file.get(), 0);
    edit(file.get());
    return path;
  };
  const auto relink = [&](const std::string& object, const std::function<void(hid_t)>& link) {
    return variant([&](hid_t file) {
      ASSERT_GE(H5Ldelete(file, object.c_str(), H5P_DEFAULT), 0) << object;
      link(file);
    });
  };
  const auto external = [&](const std::string& object, const fs::path& target,
                            const std::string& target_object) {
    return relink(object, [&](hid_t file) {
      ASSERT_GE(H5Lcreate_external(target.c_str(), target_object.c_str(), file, object.c_str(),
                                   H5P_DEFAULT, H5P_DEFAULT),
                0);
    });
  };
  const std::string mu = "/fclib_local/vectors/mu";
  struct Case {
    std::string what;
    fs::path path;
    std::vector<std::string> expected;
  };
  std::vector<Case> cases = {
      {"mu as an external link to a FIFO",
       external(mu, fifo, "/x"),
       {mu + " is an external link", fifo.string()}},
      {"mu as an external link to a valid file",
       external(mu, valid, mu),
       {mu + " is an external link", valid.string()}},
      {"mu as a soft link",
       relink(mu,
              [&](hid_t file) {
                ASSERT_GE(H5Lcreate_soft("/fclib_local/vectors/q", file, mu.c_str(), H5P_DEFAULT,
                                         H5P_DEFAULT),
                          0);
              }),
       {mu + " is a soft link to /fclib_local/vectors/q"}},
      {"the group /fclib_local as an external link",
       external("/fclib_local", fifo, "/x"),
       {"/fclib_local is an external link"}},
      {"the group W as an external link",
       external("/fclib_local/W", fifo, "/W"),
       {"/fclib_local/W is an external link"}},
      {"mu with its data in an external file (a FIFO)",
       variant([&](hid_t) {}),  // rewritten below, once the file is closed
       {mu, "external file"}},
      {"mu as a virtual dataset of a FIFO", variant([&](hid_t) {}), {mu, "virtual dataset"}},
  };
  {  // mu stored in an external file, the FIFO.
    const H5 dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    ASSERT_GE(H5Pset_external(dcpl.get(), fifo.c_str(), 0, 16), 0);
    const hsize_t two = 2;
    const H5 file = open_file(cases[5].path);
    ASSERT_GE(H5Ldelete(file.get(), mu.c_str(), H5P_DEFAULT), 0);
    const H5 space(H5Screate_simple(1, &two, nullptr), H5Sclose);
    const H5 dataset(H5Dcreate2(file.get(), mu.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                dcpl.get(), H5P_DEFAULT),
                     H5Dclose);
    ASSERT_GE(dataset.get(), 0);
  }
  {  // mu as a virtual dataset mapping /x of the FIFO.
    const hsize_t two = 2;
    const H5 space(H5Screate_simple(1, &two, nullptr), H5Sclose);
    const H5 dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
    ASSERT_GE(H5Pset_virtual(dcpl.get(), space.get(), fifo.c_str(), "/x", space.get()), 0);
    const H5 file = open_file(cases[6].path);
    ASSERT_GE(H5Ldelete(file.get(), mu.c_str(), H5P_DEFAULT), 0);
    const H5 dataset(H5Dcreate2(file.get(), mu.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                dcpl.get(), H5P_DEFAULT),
                     H5Dclose);
    ASSERT_GE(dataset.get(), 0);
  }
  // Optional objects are not skipped when they are links: the info's title, the R of equality
  // constraints (whose presence is tested).
  cases.push_back({"the title as an external link",
                   variant([&](hid_t file) {
                     make_group(file, "/fclib_local/info");
                     ASSERT_GE(
                         H5Lcreate_external(fifo.c_str(), "/t", file, "/fclib_local/info/title",
                                            H5P_DEFAULT, H5P_DEFAULT),
                         0);
                   }),
                   {"/fclib_local/info/title is an external link"}});
  cases.push_back({"R as an external link",
                   variant([&](hid_t file) {
                     ASSERT_GE(H5Lcreate_external(fifo.c_str(), "/R", file, "/fclib_local/R",
                                                  H5P_DEFAULT, H5P_DEFAULT),
                               0);
                   }),
                   {"/fclib_local/R is an external link"}});
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    for (const auto& [name, read] : all_readers(c.path)) {
      if (c.what == "the title as an external link" && name != "read_fclib_info") continue;
      SCOPED_TRACE(name);
      std::vector<std::string> expected = c.expected;
      expected.push_back(c.path.string() + ": ");
      const std::string message = prompt_refusal(name + " of " + c.what, read);
      for (const std::string& part : expected) {
        EXPECT_TRUE(contains(message, {part}));
      }
    }
  }
  EXPECT_EQ(open_hdf5_objects(), 0) << "a refused file left HDF5 objects open";
}

TEST(FclibReader, DeclaredSizesAreCheckedBeforeAnythingIsAllocated) {
  // Issue 11: tiny files declaring huge sizes took 9-25 s and gigabytes, or ended in
  // std::bad_alloc. Each size is checked against the element type, the file's size and the other
  // declared sizes before anything is allocated, and refused in well under a second.
  TempDir dir;
  int count = 0;
  const auto variant = [&] {
    const fs::path path = dir / ("declared-" + std::to_string(count++) + ".hdf5");
    write_two_contacts(path);
    return path;
  };
  struct Case {
    std::string what;
    fs::path path;
    std::vector<std::string> expected;
    bool info_only = false;     // the dataset is read by read_fclib_info only
    bool problem_only = false;  // the dataset is not read by read_fclib_info
  };
  std::vector<Case> cases;
  {  // mu declared with 2e8 entries, chunked, none written (local_csr_mu_declared_2e8.hdf5).
    const fs::path path = variant();
    replace_with_declared(path, "/fclib_local/vectors/mu", H5T_IEEE_F64LE, 200000000,
                          chunked(1024).get());
    cases.push_back({"mu declared with 2e8 entries",
                     path,
                     {"dataset /fclib_local/vectors/mu has 200000000 entries", "expected n = 2",
                      "/fclib_local/W is 6 × 6"}});
  }
  {  // The same, compressed: the declared sizes still disagree.
    const fs::path path = variant();
    replace_with_declared(path, "/fclib_local/vectors/mu", H5T_IEEE_F64LE, 200000000,
                          chunked(1024, true).get());
    cases.push_back({"mu declared with 2e8 compressed entries",
                     path,
                     {"dataset /fclib_local/vectors/mu has 200000000 entries", "expected n = 2"}});
  }
  {  // A fixed-length title of 2 GiB (local_csr_title_2GiB.hdf5).
    const fs::path path = variant();
    const H5 type(H5Tcopy(H5T_C_S1), H5Tclose);
    ASSERT_GE(H5Tset_size(type.get(), std::size_t{1} << 31), 0);
    {
      const H5 file = open_file(path);
      make_group(file.get(), "/fclib_local/info");
    }
    replace_with_declared(path, "/fclib_local/info/title", type.get(), 0, H5P_DEFAULT, true);
    cases.push_back({"a title of 2 GiB",
                     path,
                     {"dataset /fclib_local/info/title", "string of 2147483648 bytes"},
                     true});
  }
  // Datatype sizes of gigabytes (fclib_{mu,guess,spacedim}_type_size_corrupt.hdf5).
  for (const auto& [object, integer] :
       std::vector<std::pair<std::string, bool>>{{"/fclib_local/vectors/mu", false},
                                                 {"/guesses/1/r", false},
                                                 {"/fclib_local/spacedim", true}}) {
    const fs::path path = variant();
    const H5 type(H5Tcopy(integer ? H5T_STD_I32LE : H5T_IEEE_F64LE), H5Tclose);
    ASSERT_GE(H5Tset_size(type.get(), 3372220424U), 0);
    if (object == "/guesses/1/r") {
      const H5 file = open_file(path);
      make_group(file.get(), "/guesses");
      make_group(file.get(), "/guesses/1");
    }
    replace_with_declared(path, object, type.get(), object == "/guesses/1/r" ? 6 : 2);
    cases.push_back(
        {object + " of 3372220424-byte elements",
         path,
         {"dataset " + object,
          std::string(integer ? "integers" : "floating-point numbers") + " of 3372220424 bytes"},
         object == "/guesses/1/r"});
  }
  {  // W declared with 2^31 - 1 triplets (local_csr_W_declared_2pow31.hdf5): nz > nzmax.
    const fs::path path = variant();
    replace_integers(path, "/fclib_local/W/nz", {2147483647});
    cases.push_back(
        {"nz = 2^31 - 1 with nzmax = 8",
         path,
         {"dataset /fclib_local/W/nz declares 2147483647 triplets", "more than nzmax = 8"}});
  }
  {  // The same with nzmax = nz and p, i, x declared with 2^31 - 1 entries, none stored.
    const fs::path path = variant();
    replace_integers(path, "/fclib_local/W/nz", {2147483647});
    replace_integers(path, "/fclib_local/W/nzmax", {2147483647});
    for (const char* name : {"/fclib_local/W/i", "/fclib_local/W/p", "/fclib_local/W/x"}) {
      replace_with_declared(path, name, name[13] == 'x' ? H5T_IEEE_F64LE : H5T_STD_I32LE,
                            2147483647, chunked(4096).get());
    }
    cases.push_back({"p, i, x declared with 2^31 - 1 entries",
                     path,
                     {"dataset /fclib_local/W/i declares 2147483647 entries of 4 bytes",
                      "more than the", "bytes of the whole file"},
                     false,
                     true});
  }
  {  // n = 2^31 - 1 (local_csr_n_2pow31.hdf5).
    const fs::path path = variant();
    replace_integers(path, "/fclib_local/W/n", {2147483647});
    cases.push_back({"W with n = 2^31 - 1",
                     path,
                     {"matrix /fclib_local/W is 6 × 2147483647", "square 3n × 3n"}});
  }
  {  // Chunks of 2^25 doubles (256 MiB) for 2 entries.
    const fs::path path = variant();
    replace_with_declared(path, "/fclib_local/vectors/mu", H5T_IEEE_F64LE, 2,
                          chunked(hsize_t{1} << 25).get());
    cases.push_back({"mu in chunks of 256 MiB",
                     path,
                     {"dataset /fclib_local/vectors/mu is stored in chunks of 268435456 bytes"}});
  }
  {  // mu declared contiguous and never written.
    const fs::path path = variant();
    replace_with_declared(path, "/fclib_local/vectors/mu", H5T_IEEE_F64LE, 2);
    cases.push_back(
        {"mu never written", path, {"dataset /fclib_local/vectors/mu", "stores none of them"}});
  }
  {  // A non-IEEE float (x87 long double, 16 bytes) and a non-standard integer.
    const fs::path path = variant();
    replace_with_declared(path, "/fclib_local/vectors/q", H5T_NATIVE_LDOUBLE, 6);
    cases.push_back({"q of long doubles",
                     path,
                     {"dataset /fclib_local/vectors/q holds floating-point numbers of " +
                      std::to_string(H5Tget_size(H5T_NATIVE_LDOUBLE)) + " bytes"},
                     false,
                     true});
    const fs::path other = variant();
    const H5 type(H5Tcopy(H5T_STD_I32LE), H5Tclose);
    ASSERT_GE(H5Tset_precision(type.get(), 20), 0);
    replace_with_declared(other, "/fclib_local/spacedim", type.get(), 1);
    cases.push_back({"spacedim of 20-bit integers",
                     other,
                     {"dataset /fclib_local/spacedim holds integers of 4 bytes",
                      "non-standard layout (precision 20 bits"}});
  }
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    for (const auto& [name, read] : all_readers(c.path)) {
      if (c.info_only && name != "read_fclib_info") continue;
      if (c.problem_only && name == "read_fclib_info") continue;
      SCOPED_TRACE(name);
      const std::string message = prompt_refusal(name + " of " + c.what, read);
      EXPECT_TRUE(contains(message, {c.path.string() + ": "}));
      for (const std::string& part : c.expected) EXPECT_TRUE(contains(message, {part}));
    }
  }
  {  // A global problem with M declared 2^31 - 1 × 2^31 - 1 (no entries): f must have m entries.
    const fs::path path = dir / "global-huge-m.hdf5";
    {
      const H5 file = create_file(path);
      make_group(file.get(), "/fclib_global");
      write_integers(file.get(), "/fclib_global/spacedim", {3});
      write_matrix(file.get(), "/fclib_global/M", stored(2147483647, 2147483647, 0, 0, {}, {}, {}));
      write_matrix(file.get(), "/fclib_global/H", stored(2147483647, 3, 0, 0, {}, {}, {}));
      make_group(file.get(), "/fclib_global/vectors");
      write_reals(file.get(), "/fclib_global/vectors/f", {1, 2});
      write_reals(file.get(), "/fclib_global/vectors/w", {0, 0, 0});
      write_reals(file.get(), "/fclib_global/vectors/mu", {0.5});
    }
    for (const auto& read :
         std::vector<std::function<void()>>{[&] { grbd::contact::read_fclib_global(path); },
                                            [&] { grbd::contact::read_fclib_as_local(path); }}) {
      EXPECT_TRUE(contains(prompt_refusal("read of a global problem with m = 2^31 - 1", read),
                           {path.string() + ": ", "dataset /fclib_global/vectors/f has 2 entries",
                            "expected m = 2147483647"}));
    }
    // A matrix read on its own: its dimensions cannot exceed the file's size.
    EXPECT_TRUE(contains(
        prompt_refusal("read_fclib_matrix of M",
                       [&] { grbd::contact::read_fclib_matrix(path, "/fclib_global/M"); }),
        {path.string() + ": ", "matrix /fclib_global/M declares", "larger than the file's"}));
  }
  EXPECT_EQ(open_hdf5_objects(), 0) << "a refused file left HDF5 objects open";
}

TEST(FclibReader, CompressedAndChunkedDataAreRead) {
  // The size checks refuse no honest storage: chunked and deflated datasets whose data, inflated,
  // exceed the file read as the same problem.
  TempDir dir;
  const fs::path plain = dir / "plain.hdf5";
  write_two_contacts(plain);
  const fs::path packed = dir / "packed.hdf5";
  {
    const H5 file = create_file(packed);
    make_group(file.get(), "/fclib_local");
    write_integers(file.get(), "/fclib_local/spacedim", {3});
    // W: 3000 × 3000, the identity times 2 as 3000 triplets, all deflated.
    constexpr int n = 1000;
    std::vector<std::int64_t> index(3 * n);
    for (int k = 0; k < 3 * n; ++k) index[static_cast<std::size_t>(k)] = k;
    make_group(file.get(), "/fclib_local/W");
    for (const auto& [name, value] : std::vector<std::pair<std::string, std::int64_t>>{
             {"m", 3 * n}, {"n", 3 * n}, {"nz", 3 * n}, {"nzmax", 3 * n}}) {
      write_integers(file.get(), "/fclib_local/W/" + name, {value});
    }
    const auto packed_dataset = [&](const std::string& name, hid_t type, hid_t memory_type,
                                    const void* data, hsize_t size) {
      const H5 dcpl = chunked(256, true);
      const H5 space(H5Screate_simple(1, &size, nullptr), H5Sclose);
      const H5 dataset(H5Dcreate2(file.get(), name.c_str(), type, space.get(), H5P_DEFAULT,
                                  dcpl.get(), H5P_DEFAULT),
                       H5Dclose);
      ASSERT_GE(dataset.get(), 0) << name;
      ASSERT_GE(H5Dwrite(dataset.get(), memory_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), 0);
    };
    packed_dataset("/fclib_local/W/i", H5T_STD_I64LE, H5T_NATIVE_INT64, index.data(), 3 * n);
    packed_dataset("/fclib_local/W/p", H5T_STD_I64LE, H5T_NATIVE_INT64, index.data(), 3 * n);
    const std::vector<double> two(3 * n, 2.0), zero(3 * n, 0.0), mu(n, 0.5);
    packed_dataset("/fclib_local/W/x", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, two.data(), 3 * n);
    make_group(file.get(), "/fclib_local/vectors");
    packed_dataset("/fclib_local/vectors/q", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, zero.data(), 3 * n);
    packed_dataset("/fclib_local/vectors/mu", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, mu.data(), n);
  }
  EXPECT_EQ(grbd::contact::read_fclib_local(plain).mu.size(), 2U);
  const LocalProblem problem = grbd::contact::read_fclib_local(packed);
  ASSERT_EQ(problem.W.size(), 1000U);
  EXPECT_EQ(problem.W.blocks[static_cast<std::size_t>(problem.W.diagonal[999])],
            2.0 * Matrix3::Identity());
  EXPECT_EQ(problem.mu, std::vector<double>(1000, 0.5));
  EXPECT_EQ(grbd::contact::read_fclib_info(packed).contacts, 1000);
}

TEST(FclibReader, AnInvalidProblemIsRefusedNamingTheFile) {
  // Issue 11 (local_csr_W_all_zero.hdf5): a W of zeros was accepted, and the solver said
  // "validate: diagonal block (0, 0) of W ..." without naming the file. The reader validates.
  TempDir dir;
  const fs::path path = dir / "zero.hdf5";
  {
    const H5 file = create_file(path);
    make_group(file.get(), "/fclib_local");
    write_integers(file.get(), "/fclib_local/spacedim", {3});
    // W in compressed rows: 8 stored zeros.
    write_matrix(file.get(), "/fclib_local/W",
                 stored(6, 6, -2, 8, {0, 2, 3, 4, 6, 7, 8}, {0, 3, 1, 2, 0, 3, 4, 5},
                        std::vector<double>(8, 0.0)));
    make_group(file.get(), "/fclib_local/vectors");
    write_reals(file.get(), "/fclib_local/vectors/q", {-1, 0.1, 0, -0.5, 0, 0.2});
    write_reals(file.get(), "/fclib_local/vectors/mu", {0.3, 0.6});
  }
  for (const auto& [name, read] : all_readers(path)) {
    if (name == "read_fclib_info") continue;  // reads no matrix entries
    SCOPED_TRACE(name);
    EXPECT_TRUE(contains(prompt_refusal(name + " of a zero W", read),
                         {path.string() + ": ", "matrix /fclib_local/W",
                          "diagonal block (0, 0) of W has diagonal entry (0, 0) = 0"}));
  }
}

// A global problem with M = diag(1, 1, 1, 5e-324, 2, 2): 5e-324 is the smallest subnormal double,
// and M⁻¹ has 2e323 = inf on its diagonal.
GlobalProblem denormal_mass_problem() {
  GlobalProblem g;
  Eigen::VectorXd d(6);
  d << 1, 1, 1, 5e-324, 2, 2;
  g.M = Eigen::MatrixXd(d.asDiagonal()).sparseView();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6, 6);
  H(0, 0) = 1;
  H(0, 3) = -1;
  for (int k = 1; k < 6; ++k) H(k, k) = 1;
  g.H = H.sparseView();
  g.f = (Eigen::VectorXd(6) << 0, 0, -1, 0, 0, -2).finished();
  g.w = Eigen::VectorXd::Zero(6);
  g.mu = {0.5, 0.5};
  return g;
}

TEST(FclibReader, ASingularMassMatrixIsNamed) {
  // Issue 11 (global_triplet_mass_denormal.hdf5): to_local returned q with NaN and -inf, and the
  // solver blamed "q of contact 1". The reader names the file and /fclib_global/M.
  TempDir dir;
  const fs::path path = dir / "denormal.hdf5";
  const GlobalProblem g = denormal_mass_problem();
  {
    const H5 file = create_file(path);
    make_group(file.get(), "/fclib_global");
    write_integers(file.get(), "/fclib_global/spacedim", {3});
    write_matrix(file.get(), "/fclib_global/M", triplets_of(g.M));
    write_matrix(file.get(), "/fclib_global/H", triplets_of(g.H));
    make_group(file.get(), "/fclib_global/vectors");
    write_reals(file.get(), "/fclib_global/vectors/f", {0, 0, -1, 0, 0, -2});
    write_reals(file.get(), "/fclib_global/vectors/w", std::vector<double>(6, 0.0));
    write_reals(file.get(), "/fclib_global/vectors/mu", {0.5, 0.5});
  }
  EXPECT_EQ(grbd::contact::read_fclib_global(path).M.coeff(3, 3), 5e-324);
  EXPECT_TRUE(contains(
      prompt_refusal<grbd::InvalidArgument>("read_fclib_as_local of a denormal M",
                                            [&] { grbd::contact::read_fclib_as_local(path); }),
      {path.string() + ": ", "/fclib_global/M", "numerically singular",
       "M(3, 3) = 4.9406564584124654e-324"}));
}

// ---------------------------------------------------------------------------------------------
// LocalProblem: the block-sparse W, y = W x, validate(), to_local().

TEST(LocalProblem, ToBlockSparseStoresEveryDiagonalBlock) {
  // 3 contacts: blocks (0, 0), (0, 2), (1, 2), (2, 0), (2, 1), (2, 2); block (1, 1) is zero and
  // block (1, 0) holds only an explicitly stored zero.
  Eigen::MatrixXd D = Eigen::MatrixXd::Zero(9, 9);
  D.block<3, 3>(0, 0) << 4, 1, 0, 1, 5, 2, 0, 2, 6;
  D(1, 7) = 3;
  D(4, 8) = -2;
  D(6, 0) = 8;
  D(8, 5) = 9;
  D.block<3, 3>(6, 6) = 7 * Matrix3::Identity();
  SparseMatrix A = D.sparseView();
  A.coeffRef(3, 0) = 0.0;  // an explicit zero in block (1, 0)
  const BlockSparseMatrix B = grbd::contact::to_block_sparse(A);
  ASSERT_EQ(B.size(), 3U);
  EXPECT_EQ(B.row_start, (std::vector<std::int64_t>{0, 2, 4, 7}));
  EXPECT_EQ(B.column, (std::vector<std::int32_t>{0, 2, 1, 2, 0, 1, 2}));
  EXPECT_EQ(B.diagonal, (std::vector<std::int64_t>{0, 2, 6}));
  ASSERT_EQ(B.blocks.size(), 7U);
  EXPECT_EQ(B.blocks[2], Matrix3::Zero());
  EXPECT_EQ(B.blocks[1](1, 1), 3.0);
  EXPECT_EQ(B.blocks[3](1, 2), -2.0);
  EXPECT_EQ(dense(B), D);

  EXPECT_TRUE(contains(error_message<grbd::InvalidArgument>(
                           [] { grbd::contact::to_block_sparse(SparseMatrix(8, 8)); }),
                       {"to_block_sparse", "8 × 8"}));
  EXPECT_TRUE(contains(error_message<grbd::InvalidArgument>(
                           [] { grbd::contact::to_block_sparse(SparseMatrix(9, 6)); }),
                       {"9 × 6"}));
  EXPECT_EQ(grbd::contact::to_block_sparse(SparseMatrix(0, 0)).size(), 0U);
}

TEST(LocalProblem, MultiplyMatchesEigenSparseProduct) {
  grbd::test::Random random(3);
  for (const double fill : {0.0, 0.1, 0.5}) {
    const SparseMatrix W = random_symmetric_blocks(40, fill, random);
    const BlockSparseMatrix B = grbd::contact::to_block_sparse(W);
    std::vector<Vector3> x(40), y(40);
    for (Vector3& v : x) v = random.vector3();
    grbd::contact::multiply(B, x, y);
    const Eigen::VectorXd reference = W * flat(x);
    EXPECT_LE((flat(y) - reference).cwiseAbs().maxCoeff(),
              1e-14 * (1.0 + reference.cwiseAbs().maxCoeff()));
  }
  const BlockSparseMatrix B =
      grbd::contact::to_block_sparse(random_symmetric_blocks(4, 1.0, random));
  std::vector<Vector3> x(4, Vector3::Ones()), y(3);
  EXPECT_TRUE(
      contains(error_message<grbd::InvalidArgument>([&] { grbd::contact::multiply(B, x, y); }),
               {"multiply", "4 block rows", "y 3"}));
  EXPECT_TRUE(
      contains(error_message<grbd::InvalidArgument>([&] { grbd::contact::multiply(B, x, x); }),
               {"overlap"}));
}

TEST(LocalProblem, MultiplyOnFclibMatricesMatchesEigen) {
  grbd::test::Random random(5);
  for (const char* name : {kPerioBox, kCapsules}) {
    SCOPED_TRACE(name);
    const SparseMatrix W = grbd::contact::read_fclib_matrix(data_file(name), "/fclib_local/W");
    const LocalProblem problem = grbd::contact::read_fclib_local(data_file(name));
    std::vector<Vector3> lambda(problem.W.size()), y(problem.W.size());
    for (Vector3& v : lambda) v = random.vector3();
    grbd::contact::multiply(problem.W, lambda, y);
    const Eigen::VectorXd reference = W * flat(lambda);
    const double scale = reference.cwiseAbs().maxCoeff();
    EXPECT_LE((flat(y) - reference).cwiseAbs().maxCoeff(), 1e-13 * scale);
    const auto xi = grbd::contact::local_velocities(problem, lambda);
    EXPECT_LE((flat(xi) - reference - flat(problem.q)).cwiseAbs().maxCoeff(),
              1e-13 * (scale + flat(problem.q).cwiseAbs().maxCoeff()));
  }
}

TEST(LocalProblem, LocalVelocities) {
  const LocalProblem problem = small_problem();
  const std::vector<Vector3> lambda = {Vector3(1, 0, 0), Vector3(0.5, -0.25, 2), Vector3(0, 0, 3)};
  const auto xi = grbd::contact::local_velocities(problem, lambda);
  const Eigen::VectorXd reference = dense(problem.W) * flat(lambda) + flat(problem.q);
  EXPECT_LE((flat(xi) - reference).cwiseAbs().maxCoeff(), 1e-14 * reference.cwiseAbs().maxCoeff());
  const std::vector<Vector3> short_lambda(2, Vector3::Zero());
  EXPECT_TRUE(contains(error_message<grbd::InvalidArgument>(
                           [&] { grbd::contact::local_velocities(problem, short_lambda); }),
                       {"local_velocities", "lambda has 2 entries"}));
}

TEST(LocalProblem, ValidateAcceptsAValidProblem) {
  LocalProblem problem = small_problem();
  EXPECT_NO_THROW(grbd::contact::validate(problem));
  // W need not be symmetric: asymmetry between blocks (0, 1) and (1, 0), inside block (0, 0),
  // and a block (0, 1) whose transpose (1, 0) is not stored are all accepted.
  problem.W.blocks[1](0, 2) += 0.5;
  problem.W.blocks[0](0, 1) += 0.5;
  EXPECT_NO_THROW(grbd::contact::validate(problem));
  Eigen::MatrixXd D = Eigen::MatrixXd::Identity(6, 6);
  D(0, 4) = 0.5;
  EXPECT_NO_THROW(
      grbd::contact::validate(LocalProblem{grbd::contact::to_block_sparse(D.sparseView()),
                                           {Vector3::Zero(), Vector3::Zero()},
                                           {0.5, 0.5}}));
  EXPECT_NO_THROW(grbd::contact::validate(
      LocalProblem{grbd::contact::to_block_sparse(SparseMatrix(0, 0)), {}, {}}));
}

TEST(LocalProblem, ValidateNamesTheFirstBadEntry) {
  const auto refusal = [](const LocalProblem& problem) {
    return error_message<grbd::InvalidArgument>([&] { grbd::contact::validate(problem); });
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  {  // small_problem() stores all 9 blocks: blocks[5] is block (1, 2).
    LocalProblem problem = small_problem();
    problem.W.blocks[5](0, 1) = nan;
    EXPECT_TRUE(contains(refusal(problem), {"validate", "W block (1, 2) entry (0, 1) is nan"}));
  }
  {
    LocalProblem problem = small_problem();
    problem.q[2][1] = inf;
    EXPECT_TRUE(contains(refusal(problem), {"q of contact 2 entry 1 is inf"}));
  }
  {
    LocalProblem problem = small_problem();
    problem.mu[1] = -0.5;
    EXPECT_TRUE(contains(refusal(problem), {"mu of contact 1 is -0.5"}));
    problem.mu[1] = nan;
    EXPECT_TRUE(contains(refusal(problem), {"mu of contact 1 is nan"}));
  }
  {
    LocalProblem problem = small_problem();
    problem.W.blocks[static_cast<std::size_t>(problem.W.diagonal[1])](2, 2) = 0.0;
    EXPECT_TRUE(contains(refusal(problem), {"diagonal block (1, 1)", "entry (2, 2) = 0"}));
  }
  {  // A missing diagonal block is stored as zero and refused.
    Eigen::MatrixXd D = Eigen::MatrixXd::Identity(6, 6);
    D.block<3, 3>(3, 3).setZero();
    LocalProblem problem{grbd::contact::to_block_sparse(D.sparseView()),
                         {Vector3::Zero(), Vector3::Zero()},
                         {0.5, 0.5}};
    EXPECT_TRUE(contains(refusal(problem), {"diagonal block (1, 1)", "entry (0, 0) = 0"}));
  }
  {  // Sizes and structure.
    LocalProblem problem = small_problem();
    problem.q.pop_back();
    EXPECT_TRUE(contains(refusal(problem), {"3 block rows", "q 2 entries"}));
    problem = small_problem();
    problem.W.diagonal[1] = 0;
    EXPECT_TRUE(contains(refusal(problem), {"W.diagonal[1] = 0"}));
    problem = small_problem();
    problem.W.column[4] = 0;  // block row 1 now lists columns 0, 0, 2
    EXPECT_TRUE(contains(refusal(problem), {"block row 1", "not strictly increasing"}));
  }
}

// A random global problem: M = B Bᵀ + I with a sparse random B (coupled, not diagonal), H with
// every column non-zero.
GlobalProblem random_global(int m, int n, grbd::test::Random& random) {
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(m, m);
  for (int i = 0; i < m; ++i) {
    for (int j = std::max(0, i - 2); j <= i; ++j) B(i, j) = random.uniform();
  }
  GlobalProblem g;
  g.M = Eigen::MatrixXd(B * B.transpose() + Eigen::MatrixXd::Identity(m, m)).sparseView();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(m, 3 * n);
  for (int c = 0; c < 3 * n; ++c) {
    for (int r = 0; r < m; ++r) {
      if (random.uniform(0.0, 1.0) < 0.2 || r == (7 * c) % m) H(r, c) = random.uniform();
    }
  }
  g.H = H.sparseView();
  g.f = Eigen::VectorXd::NullaryExpr(m, [&] { return random.uniform(); });
  g.w = Eigen::VectorXd::NullaryExpr(3 * n, [&] { return random.uniform(); });
  g.mu.assign(static_cast<std::size_t>(n), 0.4);
  return g;
}

TEST(LocalProblem, ToLocalMatchesDenseCholesky) {
  grbd::test::Random random(13);
  const GlobalProblem g = random_global(30, 6, random);
  const Eigen::MatrixXd M(g.M), H(g.H);
  const Eigen::LLT<Eigen::MatrixXd> llt(M);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const Eigen::MatrixXd W_ref = H.transpose() * llt.solve(H);
  const Eigen::VectorXd q_ref = H.transpose() * llt.solve(g.f) + g.w;
  const LocalProblem local = grbd::contact::to_local(g);
  ASSERT_EQ(local.W.size(), 6U);
  const Eigen::MatrixXd W = dense(local.W);
  EXPECT_LE(max_abs(W - W_ref), 1e-12 * max_abs(W_ref));
  EXPECT_LE(max_abs(flat(local.q) - q_ref), 1e-12 * max_abs(q_ref));
  EXPECT_EQ(W, W.transpose());  // symmetrized
  EXPECT_EQ(local.mu, g.mu);
  EXPECT_NO_THROW(grbd::contact::validate(local));
}

TEST(LocalProblem, ToLocalDropsCancelledCouplings) {
  // M = diag(2, 3, 5, 1, 1, 1, 1); contact 0 acts on the degrees of freedom 0-2, 4 and 5, contact
  // 1 on 0-3 and 6. They share 0-2, but M⁻¹ h_0 = (0.1, 0.2, 0.3, 0, ...) and h_3 = (0.5, 0.5,
  // −0.5, 1, 0, ...) give h_0ᵀ M⁻¹ h_3 = 0.05 + 0.1 − 0.15 = 0 up to rounding: no block (0, 1).
  GlobalProblem g;
  Eigen::MatrixXd M =
      Eigen::VectorXd((Eigen::VectorXd(7) << 2, 3, 5, 1, 1, 1, 1).finished()).asDiagonal();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(7, 6);
  H.col(0) << 0.2, 0.6, 1.5, 0, 0, 0, 0;  // M⁻¹ h_0 = (0.1, 0.2, 0.3, 0, ...)
  H.col(1) << 0, 0, 0, 0, 1, 0, 0;
  H.col(2) << 0, 0, 0, 0, 0, 1, 0;
  H.col(3) << 0.5, 0.5, -0.5, 1, 0, 0, 0;  // h_0ᵀ M⁻¹ h_3 = 0.05 + 0.1 − 0.15 = 0
  H.col(4) << 0, 0, 0, 0, 0, 0, 1;
  H.col(5) << 0, 0, 0, 2, 0, 0, 0;
  g.M = M.sparseView();
  g.H = H.sparseView();
  g.f = Eigen::VectorXd::Ones(7);
  g.w = Eigen::VectorXd::Zero(6);
  g.mu = {0.5, 0.5};
  const LocalProblem local = grbd::contact::to_local(g);
  ASSERT_EQ(local.W.size(), 2U);
  EXPECT_EQ(local.W.column, (std::vector<std::int32_t>{0, 1}));  // diagonal blocks only
  const Eigen::MatrixXd W_ref = H.transpose() * M.inverse() * H;
  EXPECT_LE(max_abs(dense(local.W) - W_ref), 1e-14 * max_abs(W_ref));
}

TEST(LocalProblem, ToLocalRefusesBadInput) {
  grbd::test::Random random(17);
  const GlobalProblem good = random_global(12, 3, random);
  const auto refusal = [](const GlobalProblem& g) {
    return error_message<grbd::InvalidArgument>([&] { grbd::contact::to_local(g); });
  };
  {
    GlobalProblem g = good;
    g.M = SparseMatrix(12, 11);
    EXPECT_TRUE(contains(refusal(g), {"to_local", "M 12 × 11"}));
  }
  {
    GlobalProblem g = good;
    g.H = SparseMatrix(12, 8);
    EXPECT_TRUE(contains(refusal(g), {"H", "12 × 9", "found H 12 × 8"}));
  }
  {
    GlobalProblem g = good;
    g.f = Eigen::VectorXd::Zero(11);
    EXPECT_TRUE(contains(refusal(g), {"f with m = 12 entries", "found 11"}));
  }
  {
    GlobalProblem g = good;
    g.w = Eigen::VectorXd::Zero(10);
    EXPECT_TRUE(contains(refusal(g), {"w with 3n = 9 entries", "found 10"}));
  }
  {
    GlobalProblem g = good;
    g.mu.push_back(0.5);
    EXPECT_TRUE(contains(refusal(g), {"H", "12 × 12", "found H 12 × 9"}));
  }
  {  // Indefinite M.
    GlobalProblem g = good;
    Eigen::VectorXd d = Eigen::VectorXd::Ones(12);
    d[5] = -1.0;
    g.M = Eigen::MatrixXd(d.asDiagonal()).sparseView();
    EXPECT_TRUE(contains(refusal(g), {"M", "not positive definite"}));
  }
  {  // Asymmetric M.
    GlobalProblem g = good;
    g.M.coeffRef(3, 0) += 0.5;
    EXPECT_TRUE(contains(refusal(g), {"M", "not symmetric", "M(3, 0)"}));
  }
  {
    GlobalProblem g = good;
    g.H.coeffRef(2, 1) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_TRUE(contains(refusal(g), {"non-finite entry H(2, 1) = nan"}));
  }
  EXPECT_NO_THROW(grbd::contact::to_local(good));
}

TEST(LocalProblem, ValidateRefusesNonFiniteDiagonalsAndCorruptStructures) {
  // Issue 11: an infinite or NaN Delassus diagonal must not reach the solvers, nor a block
  // structure that multiply() and the solvers would read out of bounds.
  const auto refusal = [](const LocalProblem& problem) {
    return error_message<grbd::InvalidArgument>([&] { grbd::contact::validate(problem); });
  };
  const double inf = std::numeric_limits<double>::infinity();
  for (const double bad : {inf, -inf, std::numeric_limits<double>::quiet_NaN()}) {
    LocalProblem problem = small_problem();  // 3 contacts, all 9 blocks stored
    problem.W.blocks[static_cast<std::size_t>(problem.W.diagonal[1])](2, 2) = bad;
    EXPECT_TRUE(contains(refusal(problem),
                         {"validate", "W block (1, 1) entry (2, 2) is " + grbd::format_number(bad),
                          "expected a finite number"}));
  }
  struct Case {
    const char* what;
    std::function<void(BlockSparseMatrix&)> corrupt;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {"row_start not monotone",
       [](BlockSparseMatrix& W) { W.row_start[1] = 7; },
       {"W.row_start is not monotone", "row_start[1] = 7 > row_start[2] = 6"}},
      {"row_start not from 0",
       [](BlockSparseMatrix& W) { W.row_start[0] = 1; },
       {"W.row_start[0] = 1, expected 0"}},
      {"row_start past the blocks",
       [](BlockSparseMatrix& W) { W.row_start[3] = 12; },
       {"W.row_start[n] = 12", "9 block columns and 9 blocks"}},
      {"a block column out of range",
       [](BlockSparseMatrix& W) { W.column[8] = 3; },
       {"block row 2 has block column 3 out of range [0, 3)"}},
      {"a negative block column",
       [](BlockSparseMatrix& W) { W.column[0] = -1; },
       {"block row 0 has block column -1 out of range [0, 3)"}},
      {"a diagonal index past the row",
       [](BlockSparseMatrix& W) { W.diagonal[2] = 100; },
       {"W.diagonal[2] = 100 is not the index of block (2, 2)"}},
      {"a negative diagonal index",
       [](BlockSparseMatrix& W) { W.diagonal[0] = -1; },
       {"W.diagonal[0] = -1"}},
      {"a block missing",
       [](BlockSparseMatrix& W) { W.blocks.pop_back(); },
       {"W.row_start[n] = 9 but W has 9 block columns and 8 blocks"}},
      {"a block column too many",
       [](BlockSparseMatrix& W) { W.column.push_back(0); },
       {"10 block columns and 9 blocks"}},
      {"a diagonal index missing",
       [](BlockSparseMatrix& W) { W.diagonal.pop_back(); },
       {"3 block rows but 2 diagonal indices"}},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.what);
    LocalProblem problem = small_problem();
    ASSERT_EQ(problem.W.row_start, (std::vector<std::int64_t>{0, 3, 6, 9}));
    c.corrupt(problem.W);
    const std::string message = refusal(problem);
    for (const std::string& part : c.expected) EXPECT_TRUE(contains(message, {part}));
  }
}

TEST(LocalProblem, MultiplyRefusesOffsetsThatDisagreeWithTheBlocks) {
  // multiply() checks in O(1) and O(n) per call what would make it read out of bounds through
  // row_start; the block columns are left to validate() (see the header).
  const std::vector<Vector3> x(3, Vector3::Ones());
  std::vector<Vector3> y(3);
  const auto refusal = [&](const BlockSparseMatrix& W) {
    return error_message<grbd::InvalidArgument>([&] { grbd::contact::multiply(W, x, y); });
  };
  {
    BlockSparseMatrix W = small_problem().W;
    W.blocks.pop_back();
    EXPECT_TRUE(contains(refusal(W), {"multiply", "8 blocks and 9 block columns"}));
  }
  {
    BlockSparseMatrix W = small_problem().W;
    W.row_start = {0, 9, 3, 9};
    EXPECT_TRUE(contains(refusal(W), {"multiply", "not monotone at block row 1"}));
  }
  {
    BlockSparseMatrix W = small_problem().W;
    W.row_start[0] = -3;
    EXPECT_TRUE(contains(refusal(W), {"multiply", "runs from -3 to 9"}));
  }
  BlockSparseMatrix W = small_problem().W;
  EXPECT_NO_THROW(grbd::contact::multiply(W, x, y));
}

TEST(LocalProblem, ToLocalRefusesASingularMassAndNonFiniteResults) {
  // Issue 11 (global_triplet_mass_denormal.hdf5): M = diag(1, 1, 1, 5e-324, 2, 2) passed the
  // positive pivot test, and q came out with NaN and -inf. A pivot at most m ε times the largest
  // proves cond(M) > 1/(m ε) (the pivots of an SPD matrix lie between its extreme eigenvalues).
  const auto refusal = [](const GlobalProblem& g) {
    return error_message<grbd::InvalidArgument>([&] { grbd::contact::to_local(g); });
  };
  EXPECT_TRUE(contains(refusal(denormal_mass_problem()),
                       {"to_local", "M (6 × 6) is numerically singular",
                        "row and column 3 of M, M(3, 3) = 4.9406564584124654e-324"}));
  {  // Pivots 1 and 1e-17 of 3 × 3: 1e-17 < 3 ε = 6.7e-16.
    GlobalProblem g = denormal_mass_problem();
    Eigen::VectorXd d = Eigen::VectorXd::Ones(6);
    d[4] = 1e-17;
    g.M = Eigen::MatrixXd(d.asDiagonal()).sparseView();
    EXPECT_TRUE(contains(refusal(g), {"numerically singular", "row and column 4"}));
  }
  {  // The test is relative: M = 1e-300 I is perfectly conditioned, and W = 1e300 Hᵀ H.
    GlobalProblem g = denormal_mass_problem();
    g.M = 1e-300 * Eigen::MatrixXd::Identity(6, 6).sparseView();
    const LocalProblem local = grbd::contact::to_local(g);
    EXPECT_NEAR(dense(local.W)(1, 1), 1e300, 1e285);
    EXPECT_NO_THROW(grbd::contact::validate(local));
  }
  {  // M = I but H = 1e200: W = Hᵀ H = 1e400 overflows.
    GlobalProblem g = denormal_mass_problem();
    g.M = Eigen::MatrixXd::Identity(6, 6).sparseView();
    g.H = 1e200 * Eigen::MatrixXd::Identity(6, 6).sparseView();
    EXPECT_TRUE(contains(refusal(g), {"W = Hᵀ M⁻¹ H has a non-finite entry", "inf"}));
  }
  {  // W = 1e20 I is finite, but q = Hᵀ f = 1e310 overflows.
    GlobalProblem g = denormal_mass_problem();
    g.M = Eigen::MatrixXd::Identity(6, 6).sparseView();
    g.H = 1e10 * Eigen::MatrixXd::Identity(6, 6).sparseView();
    g.f = Eigen::VectorXd::Constant(6, 1e300);
    EXPECT_TRUE(contains(refusal(g), {"q = Hᵀ M⁻¹ f + w has a non-finite entry q[0] = inf"}));
  }
}

}  // namespace
