// Chapter 07: the products y = A x and yᵀ = xᵀ A from COO, CSR, CSC and one stored triangle,
// against dense Eigen products of the same matrices. docs/07_sparse_storage.md
#include "07_sparse_storage/sparse_formats.hpp"
#include "07_sparse_storage/sparse_products.hpp"

#include "common/error.hpp"
#include "common/random.hpp"

#include "sparse_test_support.hpp"

#include <catch2/catch.hpp>

#include <type_traits>
#include <utility>

using namespace fem::sparse;
using namespace fem::sparse::test;
using Catch::Matchers::Contains;
using fem::random_vector;

namespace {

/// Random test matrices: rectangular, with empty rows and columns and rows of every length from
/// 0 to beyond 8 (the kernels may unroll), and a few special shapes.
struct Case {
    int rows, cols;
    double density;
    unsigned seed;
};
const Case cases[] = {{9, 13, 0.3, 1}, {40, 7, 0.6, 2}, {1, 30, 0.5, 3}, {30, 1, 0.5, 4},
                      {64, 64, 0.15, 5}, {100, 250, 0.04, 6}, {13, 9, 1.0, 7}};

/// The triplets of a dense matrix with every entry split into two parts, listed in an order
/// that mixes rows and columns: the product must sum them.
CooMatrix split_triplets(const Eigen::MatrixXd& D)
{
    CooMatrix M;
    M.rows = static_cast<int>(D.rows());
    M.cols = static_cast<int>(D.cols());
    for (int pass = 0; pass < 2; ++pass)
        for (int j = static_cast<int>(D.cols()) - 1; j >= 0; --j)
            for (int i = 0; i < D.rows(); ++i)
                if (D(i, j) != 0.0)
                    M.add(i, j, pass == 0 ? 0.25 * D(i, j) : 0.75 * D(i, j));
    return M;
}

/// Checks two products of the lecture's 4×6 matrix A (lecture_csr()) against the values worked out
/// by hand: times_x(x, y) must give y = A x for x = (1, …, 6), and times_w(w, y) y = wᵀA for
/// w = (1, …, 4).
template <typename TimesX, typename TimesW>
void check_lecture_products(TimesX times_x, TimesW times_w)
{
    Eigen::VectorXd y;
    times_x((Eigen::VectorXd(6) << 1, 2, 3, 4, 5, 6).finished(), y);
    CHECK(y == (Eigen::VectorXd(4) << 50, 220, 740, 480).finished());
    times_w((Eigen::VectorXd(4) << 1, 2, 3, 4).finished(), y);
    CHECK(y == (Eigen::VectorXd(6) << 10, 80, 150, 260, 210, 320).finished());
}

/// Shapes of matrices without entries: 0×0, n×0, 0×n and n×m.
const std::pair<int, int> empty_shapes[] = {{0, 0}, {3, 0}, {0, 4}, {3, 4}};

/// For every shape of empty_shapes, product(rows, cols, x, y) with x all ones must overwrite y
/// (filled with 7s beforehand) with zeros: y = A x, or y = xᵀA when transposed, of a matrix without
/// entries.
template <typename Product>
void check_empty_products(Product product, bool transposed = false)
{
    for (auto [rows, cols] : empty_shapes) {
        CAPTURE(rows, cols);
        const int in = transposed ? rows : cols, out = transposed ? cols : rows;
        Eigen::VectorXd y = Eigen::VectorXd::Constant(out, 7.0);
        product(rows, cols, Eigen::VectorXd::Ones(in), y);
        CHECK(y == Eigen::VectorXd::Zero(out));
    }
}

/// A rows×cols CSR or CSC matrix without entries: IA holds a 0 for every slice, and one more.
template <typename Compressed>
Compressed empty_matrix(int rows, int cols)
{
    Compressed M;
    M.rows = rows;
    M.cols = cols;
    M.IA.assign((std::is_same_v<Compressed, CsrMatrix> ? rows : cols) + 1, 0);
    return M;
}

}  // namespace

TEST_CASE("the lecture's COO example (1-based on the slide) times a vector", "[ex07.1]")
{
    // {(1,1,1), (2,3,−5), (3,2,4)} on the slide is, 0-based, {(0,0,1), (1,2,−5), (2,1,4)}.
    CooMatrix M;
    M.rows = M.cols = 3;
    M.add(0, 0, 1.0);
    M.add(1, 2, -5.0);
    M.add(2, 1, 4.0);
    Eigen::VectorXd y;
    coo_times_vector(M, Eigen::Vector3d(1.0, 2.0, 3.0), y);
    CHECK(y == Eigen::Vector3d(1.0, -15.0, 8.0));
}

TEST_CASE("COO × vector: duplicates add up, any order, against the dense product", "[ex07.1]")
{
    for (const Case& c : cases) {
        CAPTURE(c.rows, c.cols);
        const Eigen::MatrixXd D = random_dense(c.rows, c.cols, c.density, c.seed, {0}, {c.cols / 2});
        const Eigen::VectorXd x = random_vector(c.cols, c.seed + 100);
        Eigen::VectorXd y = Eigen::VectorXd::Constant(3, 99.0);  // resized and overwritten
        coo_times_vector(split_triplets(D), x, y);
        CHECK(close_to_product(y, D, x));
    }
    Eigen::MatrixXd sum;
    const CooMatrix random = random_triplets(20, 15, 400, 8, sum);
    const Eigen::VectorXd x = random_vector(15, 9);
    Eigen::VectorXd y;
    coo_times_vector(random, x, y);
    CHECK(close_to_product(y, sum, x));
}

TEST_CASE("the lecture's 4×6 example, gather: CSR A x and CSC xᵀA", "[ex07.2]")
{
    check_lecture_products([](const Eigen::VectorXd& x, Eigen::VectorXd& y) { csr_times_vector(lecture_csr(), x, y); },
                           [](const Eigen::VectorXd& w, Eigen::VectorXd& y) { vector_times_csc(w, lecture_csc(), y); });
}

TEST_CASE("the lecture's 4×6 example, scatter: CSC A x and CSR xᵀA", "[ex07.3]")
{
    check_lecture_products([](const Eigen::VectorXd& x, Eigen::VectorXd& y) { csc_times_vector(lecture_csc(), x, y); },
                           [](const Eigen::VectorXd& w, Eigen::VectorXd& y) { vector_times_csr(w, lecture_csr(), y); });
}

TEST_CASE("gather: CSR A x and CSC xᵀA of random matrices against the dense product", "[ex07.2]")
{
    for (const Case& c : cases) {
        CAPTURE(c.rows, c.cols);
        const Eigen::MatrixXd D = random_dense(c.rows, c.cols, c.density, c.seed, {c.rows - 1}, {0});
        const Eigen::SparseMatrix<double> E = eigen_sparse(D);
        const Eigen::VectorXd x = random_vector(c.cols, c.seed + 200);
        const Eigen::VectorXd w = random_vector(c.rows, c.seed + 300);
        Eigen::VectorXd y;
        csr_times_vector(csr_from_eigen(E), x, y);
        CHECK(close_to_product(y, D, x));
        vector_times_csc(w, csc_from_eigen(E), y);
        CHECK(close_to_product(y, D.transpose(), w));
    }
}

TEST_CASE("scatter: CSC A x and CSR xᵀA of random matrices against the dense product", "[ex07.3]")
{
    for (const Case& c : cases) {
        CAPTURE(c.rows, c.cols);
        const Eigen::MatrixXd D = random_dense(c.rows, c.cols, c.density, c.seed, {c.rows / 3}, {c.cols - 1});
        const Eigen::SparseMatrix<double> E = eigen_sparse(D);
        const Eigen::VectorXd x = random_vector(c.cols, c.seed + 400);
        const Eigen::VectorXd w = random_vector(c.rows, c.seed + 500);
        Eigen::VectorXd y = Eigen::VectorXd::Constant(c.rows, 1e300);  // must be overwritten, not added to
        csc_times_vector(csc_from_eigen(E), x, y);
        CHECK(close_to_product(y, D, x));
        vector_times_csr(w, csr_from_eigen(E), y);
        CHECK(close_to_product(y, D.transpose(), w));
    }
}

TEST_CASE("the gather kernel on views of raw arrays", "[ex07.2]")
{
    const std::vector<double> x{1, 2, 3, 4, 5, 6};
    std::vector<double> y(4, -1.0);
    gather_product(view(lecture_csr()), x, y);
    CHECK(y == std::vector<double>{50, 220, 740, 480});
}

TEST_CASE("the scatter kernel on views of raw arrays", "[ex07.3]")
{
    const std::vector<double> x{1, 2, 3, 4, 5, 6};
    std::vector<double> z(4, -1.0);
    scatter_product(view(lecture_csc()), x, z);
    CHECK(z == std::vector<double>{50, 220, 740, 480});
}

TEST_CASE("COO products of empty matrices: 0×0, n×0 gives zeros, 0×n gives an empty vector", "[ex07.1]")
{
    check_empty_products([](int rows, int cols, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        CooMatrix T;
        T.rows = rows;
        T.cols = cols;
        coo_times_vector(T, x, y);
    });
}

TEST_CASE("gather products of empty matrices: CSR A x", "[ex07.2]")
{
    check_empty_products([](int rows, int cols, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        csr_times_vector(empty_matrix<CsrMatrix>(rows, cols), x, y);
    });
}

TEST_CASE("scatter products of empty matrices: CSC A x and CSR xᵀA", "[ex07.3]")
{
    check_empty_products([](int rows, int cols, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
        csc_times_vector(empty_matrix<CscMatrix>(rows, cols), x, y);
    });
    check_empty_products(
        [](int rows, int cols, const Eigen::VectorXd& w, Eigen::VectorXd& y) {
            vector_times_csr(w, empty_matrix<CsrMatrix>(rows, cols), y);
        },
        true);
}

TEST_CASE("products refuse vectors of the wrong size and y = x", "[validate]")
{
    const CsrMatrix R = lecture_csr();
    const CscMatrix C = lecture_csc();
    const CooMatrix T = csr_to_coo(R);
    Eigen::VectorXd y;
    const Eigen::VectorXd x5 = Eigen::VectorXd::Ones(5);
    CHECK_THROWS_WITH(csr_times_vector(R, x5, y), Contains("x has 5 entries") && Contains("needs 6"));
    CHECK_THROWS_WITH(csc_times_vector(C, x5, y), Contains("x has 5 entries"));
    CHECK_THROWS_WITH(coo_times_vector(T, x5, y), Contains("x has 5 entries"));
    CHECK_THROWS_WITH(vector_times_csc(x5, C, y), Contains("x has 5 entries") && Contains("needs 4"));
    CHECK_THROWS_AS(vector_times_csr(x5, R, y), fem::Error);

    CsrMatrix square;
    square.rows = square.cols = 2;
    square.IA = {0, 1, 2};
    square.JA = {0, 1};
    square.A = {1.0, 2.0};
    Eigen::VectorXd v = Eigen::VectorXd::Ones(2);
    CHECK_THROWS_WITH(csr_times_vector(square, v, v), Contains("same vector"));
    CHECK_THROWS_WITH(symmetric_times_vector(square, v, v), Contains("same vector"));

    const std::vector<double> a{1, 2, 3, 4, 5, 6};
    std::vector<double> small(3);
    CHECK_THROWS_WITH(gather_product(view(R), a, small), Contains("y has 3 entries"));
    std::vector<double> overlap(10);
    CHECK_THROWS_WITH(gather_product(view(R), std::span<const double>(overlap.data(), 6),
                                     std::span<double>(overlap.data() + 5, 4)),
                      Contains("share memory"));

    CsrMatrix broken = R;
    broken.IA.pop_back();
    CHECK_THROWS_WITH(csr_times_vector(broken, Eigen::VectorXd::Ones(6), y), Contains("IA has 4 entries"));
}

TEST_CASE("symmetric product from the lower triangle equals the full product", "[ex07.6]")
{
    for (auto [n, density, seed] : {std::tuple{1, 1.0, 1u}, std::tuple{2, 1.0, 2u}, std::tuple{12, 0.3, 3u},
                                    std::tuple{50, 0.2, 4u}, std::tuple{200, 0.03, 5u}}) {
        CAPTURE(n);
        Eigen::MatrixXd B = random_dense(n, n, density, seed, {n / 2}, {n / 2});
        const Eigen::MatrixXd S = B + B.transpose();  // symmetric, row and column n/2 empty
        const Eigen::VectorXd x = random_vector(n, seed + 10);
        const CsrMatrix L = lower_triangle(csr_from_eigen(eigen_sparse(S)));
        Eigen::VectorXd y = Eigen::VectorXd::Constant(n, 1e300);
        symmetric_times_vector(L, x, y);
        CHECK(close_to_product(y, S, x));
    }
}

TEST_CASE("symmetric product: missing diagonal entries, empty rows, and a stiffness-like matrix",
          "[ex07.6]")
{
    // A 1D Laplacian-like tridiagonal matrix with the diagonal of rows 0 and 3 not stored, and row 2
    // and column 2 empty.
    Eigen::MatrixXd S = Eigen::MatrixXd::Zero(5, 5);
    S(0, 1) = S(1, 0) = -1.0;
    S(1, 1) = 2.0;
    S(3, 4) = S(4, 3) = -1.5;
    S(4, 4) = 3.0;
    S(4, 0) = S(0, 4) = 0.5;
    const CsrMatrix L = lower_triangle(csr_from_eigen(eigen_sparse(S)));
    const Eigen::VectorXd x = (Eigen::VectorXd(5) << 1, -2, 3, 0.5, 4).finished();
    Eigen::VectorXd y;
    symmetric_times_vector(L, x, y);
    CHECK(close_to_product(y, S, x));

    // Against Eigen's own symmetric product on the same stored triangle.
    const Eigen::MatrixXd D = random_dense(80, 80, 0.1, 9);
    const Eigen::MatrixXd K = D * D.transpose() + Eigen::MatrixXd::Identity(80, 80);
    const Eigen::SparseMatrix<double> E = eigen_sparse(K);
    const Eigen::VectorXd z = random_vector(80, 10);
    symmetric_times_vector(lower_triangle(csr_from_eigen(E)), z, y);
    const Eigen::VectorXd eigen_y = E.selfadjointView<Eigen::Lower>() * z;
    CHECK((y - eigen_y).norm() <= 1e-13 * (K.cwiseAbs() * z.cwiseAbs()).norm());

    CsrMatrix empty;
    symmetric_times_vector(empty, Eigen::VectorXd(), y);
    CHECK(y.size() == 0);
}

TEST_CASE("symmetric product reads only the lower triangle: the full matrix gives the same y", "[ex07.6]")
{
    const Eigen::MatrixXd B = random_dense(40, 40, 0.2, 21, {7}, {7});
    const Eigen::MatrixXd S = B + B.transpose();
    const Eigen::VectorXd x = random_vector(40, 22);
    Eigen::VectorXd y;
    symmetric_times_vector(csr_from_eigen(eigen_sparse(S)), x, y);
    CHECK(close_to_product(y, S, x));

    // Anything above the diagonal is ignored: here it is unrelated to the lower triangle.
    Eigen::MatrixXd M = S;
    M.triangularView<Eigen::StrictlyUpper>() = random_dense(40, 40, 0.5, 23);
    symmetric_times_vector(csr_from_eigen(eigen_sparse(M)), x, y);
    CHECK(close_to_product(y, S, x));
}

TEST_CASE("symmetric product refuses a non-square matrix", "[validate]")
{
    Eigen::VectorXd y;
    CHECK_THROWS_WITH(symmetric_times_vector(lecture_csr(), Eigen::VectorXd::Ones(6), y),
                      Contains("4×6") && Contains("square"));
}

TEST_CASE("the byte model of an SpMV", "[cost]")
{
    // CSR of a 4×6 matrix with 8 entries: 8 × 12 + 5 × 4 + (6 + 4) × 8.
    CHECK(spmv_bytes(8, 4, 5, 6, 4) == 96 + 20 + 80);
    // COO: two indices per entry, no pointers.
    CHECK(spmv_bytes(8, 8, 0, 6, 4) == 128 + 80);
}
