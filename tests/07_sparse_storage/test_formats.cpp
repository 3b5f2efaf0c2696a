// Chapter 07: COO → CSR, the transpose (CSR ↔ CSC), the checks of validate, and the conversions
// to and from Eigen. References: the lecture's example worked out by hand, and Eigen's own
// setFromTriplets and storage-order conversions. docs/07_sparse_storage.md
#include "07_sparse_storage/sparse_formats.hpp"

#include "common/error.hpp"

#include "sparse_test_support.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>

using namespace fem::sparse;
using namespace fem::sparse::test;
using Catch::Matchers::Contains;

namespace {

/// The CSR arrays Eigen makes of the same matrix: a row-major copy of a column-major one.
CsrMatrix eigen_csr(const Eigen::SparseMatrix<double>& E)
{
    Eigen::SparseMatrix<double, Eigen::RowMajor, int> R = E;
    R.makeCompressed();
    CsrMatrix M;
    M.rows = static_cast<int>(R.rows());
    M.cols = static_cast<int>(R.cols());
    M.A.assign(R.valuePtr(), R.valuePtr() + R.nonZeros());
    M.IA.assign(R.outerIndexPtr(), R.outerIndexPtr() + R.outerSize() + 1);
    M.JA.assign(R.innerIndexPtr(), R.innerIndexPtr() + R.nonZeros());
    return M;
}

/// The CSC arrays of Eigen's column-major matrix.
CscMatrix eigen_csc(Eigen::SparseMatrix<double> E)
{
    E.makeCompressed();
    CscMatrix M;
    M.rows = static_cast<int>(E.rows());
    M.cols = static_cast<int>(E.cols());
    M.A.assign(E.valuePtr(), E.valuePtr() + E.nonZeros());
    M.IA.assign(E.outerIndexPtr(), E.outerIndexPtr() + E.outerSize() + 1);
    M.JA.assign(E.innerIndexPtr(), E.innerIndexPtr() + E.nonZeros());
    return M;
}

template <typename Compressed>
void require_same_arrays(const Compressed& got, const Compressed& want)
{
    REQUIRE(got.rows == want.rows);
    REQUIRE(got.cols == want.cols);
    REQUIRE(got.IA == want.IA);
    REQUIRE(got.JA == want.JA);
    REQUIRE(got.A.size() == want.A.size());
    for (std::size_t k = 0; k < got.A.size(); ++k)
        REQUIRE(got.A[k] == Approx(want.A[k]).epsilon(1e-14).margin(1e-14));
}

/// The triplets of a dense matrix's nonzeros, in a shuffled order.
CooMatrix shuffled_triplets(const Eigen::MatrixXd& D, unsigned seed)
{
    CooMatrix M;
    M.rows = static_cast<int>(D.rows());
    M.cols = static_cast<int>(D.cols());
    for (int i = 0; i < D.rows(); ++i)
        for (int j = 0; j < D.cols(); ++j)
            if (D(i, j) != 0.0)
                M.add(i, j, D(i, j));
    std::vector<std::size_t> order(M.entries());
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin(), order.end(), std::mt19937(seed));
    CooMatrix S;
    S.rows = M.rows;
    S.cols = M.cols;
    for (std::size_t k : order)
        S.add(M.row[k], M.col[k], M.value[k]);
    return S;
}

}  // namespace

TEST_CASE("the lecture's 4×6 example: COO → CSR gives A, IA and the corrected JA", "[ex07.5]")
{
    const CsrMatrix M = coo_to_csr(shuffled_triplets(lecture_matrix(), 7));
    CHECK(M.rows == 4);
    CHECK(M.cols == 6);
    CHECK(M.A == std::vector<double>{10, 20, 30, 40, 50, 60, 70, 80});
    CHECK(M.IA == std::vector<int>{0, 2, 4, 7, 8});
    CHECK(M.JA == std::vector<int>{0, 1, 1, 3, 2, 3, 4, 5});
    CHECK_NOTHROW(validate(M));
}

TEST_CASE("the lecture's JA as printed (7 entries for 8 values) is rejected by validate", "[validate]")
{
    CsrMatrix M = lecture_csr();
    M.JA = {0, 1, 3, 2, 3, 4, 5};
    CHECK_THROWS_WITH(validate(M), Contains("JA 7 indices") && Contains("8"));
    CHECK_NOTHROW(validate(lecture_csr()));
    CHECK_NOTHROW(validate(lecture_csc()));
    CHECK(to_eigen(lecture_csr()).toDense() == lecture_matrix());
    CHECK(to_eigen(lecture_csc()).toDense() == lecture_matrix());
}

TEST_CASE("the lecture's example: CSR → CSC and back by the counting-sort transpose", "[ex07.4]")
{
    const CscMatrix C = csr_to_csc(lecture_csr());
    CHECK(C.rows == 4);
    CHECK(C.cols == 6);
    CHECK(C.A == lecture_csc().A);
    CHECK(C.IA == lecture_csc().IA);
    CHECK(C.JA == lecture_csc().JA);

    const CsrMatrix R = csc_to_csr(lecture_csc());
    CHECK(R.A == lecture_csr().A);
    CHECK(R.IA == lecture_csr().IA);
    CHECK(R.JA == lecture_csr().JA);

    // Aᵀ in CSR has the CSC arrays of A, with rows and columns exchanged.
    const CsrMatrix T = transpose(lecture_csr());
    CHECK(T.rows == 6);
    CHECK(T.cols == 4);
    CHECK(T.A == lecture_csc().A);
    CHECK(T.IA == lecture_csc().IA);
    CHECK(T.JA == lecture_csc().JA);
}

TEST_CASE("COO → CSR of random triplets with many duplicates, in random order, matches Eigen's "
          "setFromTriplets", "[ex07.5]")
{
    for (auto [rows, cols, entries, seed] : {std::tuple{7, 5, 60, 1u}, std::tuple{30, 41, 400, 2u},
                                             std::tuple{50, 3, 500, 3u}, std::tuple{1, 9, 30, 4u},
                                             std::tuple{200, 200, 3000, 5u}}) {
        CAPTURE(rows, cols, entries);
        Eigen::MatrixXd sum;
        const CooMatrix coo = random_triplets(rows, cols, entries, seed, sum);
        std::vector<Eigen::Triplet<double>> triplets;
        for (std::size_t k = 0; k < coo.entries(); ++k)
            triplets.emplace_back(coo.row[k], coo.col[k], coo.value[k]);
        Eigen::SparseMatrix<double> E(rows, cols);
        E.setFromTriplets(triplets.begin(), triplets.end());

        const CsrMatrix M = coo_to_csr(coo);
        CHECK_NOTHROW(validate(M));
        require_same_arrays(M, eigen_csr(E));
        CHECK(to_eigen(M).toDense().isApprox(sum, 1e-14));
    }
}

TEST_CASE("COO → CSR: unsorted input, empty rows and columns, a row given only by duplicates", "[ex07.5]")
{
    CooMatrix coo;
    coo.rows = 6;
    coo.cols = 5;
    // Rows 0, 2 and 5 are empty; column 1 is empty; row 3 is one entry (3, 4) split in three.
    coo.add(4, 3, 2.0);
    coo.add(3, 4, 1.0);
    coo.add(1, 2, -1.0);
    coo.add(4, 0, 5.0);
    coo.add(3, 4, 0.5);
    coo.add(1, 0, 7.0);
    coo.add(3, 4, 0.25);
    coo.add(4, 2, -3.0);
    const CsrMatrix M = coo_to_csr(coo);
    CHECK(M.IA == std::vector<int>{0, 0, 2, 2, 3, 6, 6});
    CHECK(M.JA == std::vector<int>{0, 2, 4, 0, 2, 3});
    CHECK(M.A == std::vector<double>{7.0, -1.0, 1.75, 5.0, -3.0, 2.0});
}

TEST_CASE("COO → CSR: duplicates that cancel leave an explicitly stored zero", "[ex07.5]")
{
    CooMatrix coo;
    coo.rows = coo.cols = 2;
    coo.add(0, 1, 0.5);
    coo.add(1, 1, 3.0);
    coo.add(0, 1, -0.5);
    const CsrMatrix M = coo_to_csr(coo);
    CHECK(M.IA == std::vector<int>{0, 1, 2});
    CHECK(M.JA == std::vector<int>{1, 1});
    CHECK(M.A == std::vector<double>{0.0, 3.0});
}

TEST_CASE("COO → CSR of empty matrices: 0×0, n×0, 0×n and n×m without entries", "[ex07.5]")
{
    for (auto [rows, cols] : {std::pair{0, 0}, std::pair{3, 0}, std::pair{0, 4}, std::pair{2, 5}}) {
        CAPTURE(rows, cols);
        CooMatrix coo;
        coo.rows = rows;
        coo.cols = cols;
        const CsrMatrix M = coo_to_csr(coo);
        CHECK(M.rows == rows);
        CHECK(M.cols == cols);
        CHECK(M.IA == std::vector<int>(rows + 1, 0));
        CHECK(M.JA.empty());
        CHECK(M.A.empty());
        CHECK_NOTHROW(validate(M));
    }
    // With one entry the smallest nonempty case, 1×1.
    CooMatrix one;
    one.rows = one.cols = 1;
    one.add(0, 0, 4.0);
    one.add(0, 0, -1.0);
    const CsrMatrix M = coo_to_csr(one);
    CHECK(M.IA == std::vector<int>{0, 1});
    CHECK(M.JA == std::vector<int>{0});
    CHECK(M.A == std::vector<double>{3.0});
}

TEST_CASE("COO: out-of-range indices, mismatched arrays and non-finite values raise fem::Error", "[validate]")
{
    CooMatrix coo;
    coo.rows = 3;
    coo.cols = 4;
    coo.add(0, 0, 1.0);
    coo.add(2, 3, 1.0);
    CHECK_NOTHROW(validate(coo));

    CooMatrix bad = coo;
    bad.add(3, 1, 1.0);
    CHECK_THROWS_WITH(coo_to_csr(bad), Contains("entry k = 2") && Contains("row 3") && Contains("0 ≤ row < 3"));
    bad = coo;
    bad.add(1, 4, 1.0);
    CHECK_THROWS_WITH(coo_to_csr(bad), Contains("entry k = 2") && Contains("column 4"));
    bad = coo;
    bad.add(-1, 0, 1.0);
    CHECK_THROWS_AS(coo_to_csr(bad), fem::Error);
    bad = coo;
    bad.add(0, -2, 1.0);
    CHECK_THROWS_AS(validate(bad), fem::Error);
    bad = coo;
    bad.add(1, 1, std::numeric_limits<double>::quiet_NaN());
    CHECK_THROWS_WITH(coo_to_csr(bad), Contains("not finite"));
    bad = coo;
    bad.row.push_back(0);
    CHECK_THROWS_WITH(coo_to_csr(bad), Contains("3 row indices"));
    bad = coo;
    bad.rows = -1;
    CHECK_THROWS_WITH(validate(bad), Contains("negative"));
}

TEST_CASE("CSR and CSC: validate names the offending entry", "[validate]")
{
    const CsrMatrix good = lecture_csr();
    CsrMatrix M = good;
    M.JA[5] = 6;
    CHECK_THROWS_WITH(validate(M), Contains("entry k = 5") && Contains("row 2") && Contains("[0, 6)"));
    M = good;
    M.JA[4] = -1;
    CHECK_THROWS_AS(validate(M), fem::Error);
    M = good;
    std::swap(M.JA[4], M.JA[5]);  // row 2 unsorted
    CHECK_THROWS_WITH(validate(M), Contains("row 2") && Contains("increase strictly"));
    M = good;
    M.JA[3] = 1;  // row 1 holds column 1 twice
    CHECK_THROWS_WITH(validate(M), Contains("row 1") && Contains("no duplicates"));
    M = good;
    M.IA = {0, 2, 4, 8};
    CHECK_THROWS_WITH(validate(M), Contains("IA has 4 entries") && Contains("5"));
    M = good;
    M.IA = {0, 4, 2, 7, 8};
    CHECK_THROWS_WITH(validate(M), Contains("IA[2] = 2 < IA[1] = 4"));
    M = good;
    M.IA = {1, 2, 4, 7, 8};
    CHECK_THROWS_WITH(validate(M), Contains("IA[0] = 1"));
    M = good;
    M.A[7] = std::numeric_limits<double>::infinity();
    CHECK_THROWS_WITH(validate(M), Contains("A[7]") && Contains("not finite"));
    M = good;
    M.cols = -6;
    CHECK_THROWS_AS(validate(M), fem::Error);

    CscMatrix C = lecture_csc();
    C.JA[2] = 4;
    CHECK_THROWS_WITH(validate(C), Contains("CSC") && Contains("column 1") && Contains("row JA[2] = 4"));
    C = lecture_csc();
    C.IA.pop_back();
    CHECK_THROWS_WITH(validate(C), Contains("columns + 1 = 7"));
    CHECK_THROWS_AS(to_eigen(C), fem::Error);
    CHECK_THROWS_AS(csc_to_csr(C), fem::Error);
}

TEST_CASE("transpose of random rectangular matrices matches Eigen's storage-order conversion", "[ex07.4]")
{
    for (auto [rows, cols, density, seed] : {std::tuple{9, 13, 0.3, 11u}, std::tuple{40, 7, 0.5, 12u},
                                             std::tuple{1, 25, 0.6, 13u}, std::tuple{25, 1, 0.6, 14u},
                                             std::tuple{120, 90, 0.05, 15u}}) {
        CAPTURE(rows, cols);
        const Eigen::MatrixXd D = random_dense(rows, cols, density, seed, {0, rows / 2}, {cols - 1});
        const Eigen::SparseMatrix<double> E = eigen_sparse(D);
        const CsrMatrix R = eigen_csr(E);
        const CscMatrix C = eigen_csc(E);

        require_same_arrays(csr_to_csc(R), C);
        require_same_arrays(csc_to_csr(C), R);
        const Eigen::SparseMatrix<double> Et = E.transpose();
        require_same_arrays(transpose(R), eigen_csr(Et));
        require_same_arrays(transpose(transpose(R)), R);
    }
}

TEST_CASE("transpose of empty matrices: 0×0, n×0, 0×n, and all-zero n×m", "[ex07.4]")
{
    for (auto [rows, cols] : {std::pair{0, 0}, std::pair{4, 0}, std::pair{0, 3}, std::pair{3, 5}}) {
        CAPTURE(rows, cols);
        CsrMatrix M;
        M.rows = rows;
        M.cols = cols;
        M.IA.assign(rows + 1, 0);
        const CscMatrix C = csr_to_csc(M);
        CHECK(C.IA == std::vector<int>(cols + 1, 0));
        CHECK(C.JA.empty());
        const CsrMatrix T = transpose(M);
        CHECK(T.rows == cols);
        CHECK(T.cols == rows);
        CHECK(T.IA == std::vector<int>(cols + 1, 0));
    }
    // A nonempty case that a stub cannot pass: one entry.
    CsrMatrix one;
    one.rows = 2;
    one.cols = 3;
    one.IA = {0, 0, 1};
    one.JA = {2};
    one.A = {5.0};
    const CscMatrix C = csr_to_csc(one);
    CHECK(C.IA == std::vector<int>{0, 0, 0, 1});
    CHECK(C.JA == std::vector<int>{1});
    CHECK(C.A == std::vector<double>{5.0});
}

TEST_CASE("transpose_compressed sorts unsorted slices and keeps repeated inner indices", "[ex07.4]")
{
    // Two slices with unsorted inner indices, the second with index 0 twice.
    const std::vector<double> A{1, 2, 3, 4, 5, 6};
    const std::vector<int> IA{0, 3, 6};
    const std::vector<int> JA{2, 0, 1, 0, 3, 0};
    std::vector<double> At;
    std::vector<int> IAt, JAt;
    transpose_compressed(CompressedView{2, 4, A, IA, JA}, At, IAt, JAt);
    CHECK(IAt == std::vector<int>{0, 3, 4, 5, 6});
    CHECK(JAt == std::vector<int>{0, 1, 1, 0, 0, 1});
    CHECK(At == std::vector<double>{2, 4, 6, 3, 1, 5});
}

TEST_CASE("transpose_compressed refuses inconsistent arrays and out-of-range indices", "[validate]")
{
    const std::vector<double> A{1, 2, 3};
    const std::vector<int> IA{0, 2, 3};
    std::vector<double> At;
    std::vector<int> IAt, JAt;
    const std::vector<int> out_of_range{0, 4, 1};
    CHECK_THROWS_WITH(transpose_compressed(CompressedView{2, 4, A, IA, out_of_range}, At, IAt, JAt),
                      Contains("JA[1] = 4") && Contains("[0, 4)"));
    const std::vector<int> short_JA{0, 1};
    CHECK_THROWS_AS(transpose_compressed(CompressedView{2, 4, A, IA, short_JA}, At, IAt, JAt), fem::Error);
    const std::vector<int> JA{0, 1, 2};
    const std::vector<int> decreasing{0, 2, 1, 3};
    CHECK_THROWS_WITH(transpose_compressed(CompressedView{3, 4, A, decreasing, JA}, At, IAt, JAt),
                      Contains("IA[2] = 1 < IA[1] = 2") && Contains("must not decrease"));
    const std::vector<int> past_the_end{0, 4, 3};
    CHECK_THROWS_WITH(transpose_compressed(CompressedView{2, 4, A, past_the_end, JA}, At, IAt, JAt),
                      Contains("IA[1] = 4") && Contains("past the 3 stored entries"));
}

TEST_CASE("conversions to and from Eigen keep every entry, explicit zeros included", "[eigen]")
{
    const Eigen::MatrixXd D = random_dense(17, 11, 0.3, 21, {3}, {4});
    const Eigen::SparseMatrix<double> E = eigen_sparse(D);
    const CsrMatrix R = csr_from_eigen(E);
    const CscMatrix C = csc_from_eigen(E);
    CHECK_NOTHROW(validate(R));
    CHECK_NOTHROW(validate(C));
    CHECK(R.nonzeros() == E.nonZeros());
    CHECK(to_eigen(R).toDense() == D);
    CHECK(to_eigen(C).toDense() == D);

    // An uncompressed Eigen matrix (after insert) with a stored zero.
    Eigen::SparseMatrix<double> U(3, 3);
    U.reserve(Eigen::VectorXi::Constant(3, 2));
    U.insert(2, 0) = 1.5;
    U.insert(0, 1) = 0.0;
    U.insert(1, 2) = -2.0;
    const CsrMatrix Ru = csr_from_eigen(U);
    CHECK(Ru.IA == std::vector<int>{0, 1, 2, 3});
    CHECK(Ru.JA == std::vector<int>{1, 2, 0});
    CHECK(Ru.A == std::vector<double>{0.0, -2.0, 1.5});
    CHECK(csc_from_eigen(U).JA == std::vector<int>{2, 0, 1});

    CHECK(to_eigen(CsrMatrix{}).rows() == 0);
    Eigen::SparseMatrix<double> bad(2, 2);
    bad.insert(1, 1) = std::numeric_limits<double>::quiet_NaN();
    CHECK_THROWS_WITH(csr_from_eigen(bad), Contains("not finite"));
}

TEST_CASE("CSR → COO → CSR and the lower triangle", "[formats]")
{
    const CsrMatrix M = lecture_csr();
    const CooMatrix coo = csr_to_coo(M);
    CHECK(coo.row == std::vector<int>{0, 0, 1, 1, 2, 2, 2, 3});
    CHECK(coo.col == M.JA);
    CHECK(coo.value == M.A);

    const Eigen::MatrixXd D = random_dense(12, 12, 0.4, 31, {5});
    const CsrMatrix L = lower_triangle(csr_from_eigen(eigen_sparse(D)));
    CHECK_NOTHROW(validate(L));
    const Eigen::MatrixXd lower = D.triangularView<Eigen::Lower>();
    CHECK(to_eigen(L).toDense() == lower);
    CHECK_THROWS_WITH(lower_triangle(lecture_csr()), Contains("4×6"));
}
