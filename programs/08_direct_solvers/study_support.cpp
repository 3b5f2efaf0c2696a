// ch08_direct_solvers: what several studies share: the sparse test matrices, the alternating
// timer, and CHOLMOD, the reference (not course material), through Eigen's CholmodSupport.
// docs/08_direct_solvers.md
#include "studies.hpp"

#include "08_direct_solvers/model_problems.hpp"

#include "common/error.hpp"
#include "common/timer.hpp"

#ifdef FEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include <algorithm>
#include <tuple>

namespace fem::direct::study {

std::vector<int> family_sizes(const std::string& family, bool quick)
{
    // about 10k, 50k and 160k unknowns (quick: a few hundred to a few thousand)
    if (family == "2D Laplacian")
        return quick ? std::vector<int>{30, 60} : std::vector<int>{100, 224, 400};
    if (family == "3D Laplacian")
        return quick ? std::vector<int>{8, 14} : std::vector<int>{22, 37, 54};
    return quick ? std::vector<int>{4, 7} : std::vector<int>{14, 25, 37};
}

long long family_unknowns(const std::string& family, int size)
{
    if (family == "2D Laplacian")
        return static_cast<long long>(size) * size;
    if (family == "3D Laplacian")
        return static_cast<long long>(size) * size * size;
    return 3LL * size * (size + 1) * (size + 1);
}

Problem make_problem(const std::string& family, int size)
{
    Problem p{family, size, {}, {}};
    p.A = family == "2D Laplacian" ? laplacian_2d(size)
          : family == "3D Laplacian" ? laplacian_3d(size)
                                     : box_stiffness(size, rubber);
    p.E = sparse::to_eigen(p.A);
    return p;
}

std::string size_text(const Problem& p)
{
    if (p.family == "3D elasticity")
        return str(p.size, "^3 cubes");
    return p.family == "2D Laplacian" ? str(p.size, "^2") : str(p.size, "^3");
}

long long lower_nonzeros(const sparse::CscMatrix& A)
{
    long long count = 0;
    for (int j = 0; j < A.cols; ++j)
        for (int k = A.IA[j]; k < A.IA[j + 1]; ++k)
            count += A.JA[k] >= j;
    return count;
}

std::pair<double, double> alternating_best_times(const std::function<void()>& a, const std::function<void()>& b,
                                                 double min_seconds, int max_rounds)
{
    double best_a = 1e300, best_b = b ? 1e300 : 0.0;
    Timer total;
    for (int round = 0; round < max_rounds && (round == 0 || total.seconds() < min_seconds); ++round) {
        Timer once;
        a();
        best_a = std::min(best_a, once.seconds());
        if (b) {
            once.restart();
            b();
            best_b = std::min(best_b, once.seconds());
        }
    }
    return {best_a, best_b};
}

#ifdef FEM_HAVE_CHOLMOD
namespace {

std::string cholmod_ordering_name(int ordering)
{
    switch (ordering) {
    case CHOLMOD_NATURAL: return "natural";
    case CHOLMOD_AMD: return "AMD";
    case CHOLMOD_METIS: return "METIS";
    case CHOLMOD_NESDIS: return "NESDIS";
    default: return str("method ", ordering);
    }
}

}  // namespace

CholmodResult run_cholmod(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b, bool natural,
                          bool analyse_only, const std::function<void()>& other_solve)
{
    CholmodResult r;
    Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>, Eigen::Lower> chol;
    if (natural) {
        chol.cholmod().nmethods = 1;
        chol.cholmod().method[0].ordering = CHOLMOD_NATURAL;
    }
    Timer timer;
    chol.analyzePattern(A);
    r.analyse = timer.seconds();
    const cholmod_common& c = chol.cholmod();
    r.ordering = natural ? "ours (same P)" : "CHOLMOD's: " + cholmod_ordering_name(c.method[c.selected].ordering);
    r.nonzeros = c.lnz;
    r.flops = c.fl;
    r.ran = true;
    if (analyse_only)
        return r;
    r.factor = timed([&] { chol.factorize(A); });
    if (chol.info() != Eigen::Success)
        throw Error("CHOLMOD: the factorization failed (the matrix is not positive definite)");
    std::tie(r.solve, r.other_solve) = alternating_best_times([&] { r.x = chol.solve(b); }, other_solve);
    return r;
}
#endif

}  // namespace fem::direct::study
