// ch09_conjugate_gradient: what several studies share: the test problems and our iterative methods.
// docs/09_conjugate_gradient.md
#include "studies.hpp"

#include "08_direct_solvers/model_problems.hpp"

#include "common/timer.hpp"

#include <map>
#include <sstream>

namespace fem::cg::study {

Problem make_problem(const std::string& key, int size, const Settings& settings)
{
    Problem p;
    p.key = key;
    if (key == "lap2") {
        p.label = "2D Laplacian";
        p.A = sparse::to_eigen(direct::laplacian_2d(size));
        p.b = Eigen::VectorXd::Ones(p.A.rows());  // a uniform source
    } else if (key == "lap3") {
        p.label = "3D Laplacian";
        p.three_d = true;
        p.A = sparse::to_eigen(direct::laplacian_3d(size));
        p.b = Eigen::VectorXd::Ones(p.A.rows());
    } else {
        p.label = "elastic box";
        p.three_d = true;
        const ElasticBox box = clamped_box(size, elastic::lame_parameters(settings.youngs, settings.poisson),
                                           settings.density);
        p.A = box.K;
        p.b = box.f;  // its weight
    }
    p.A.makeCompressed();
    return p;
}

std::string scientific(double value)
{
    std::ostringstream out;
    out.precision(0);
    out << std::scientific << value;
    return out.str();
}

double relative_error(const Eigen::VectorXd& x, const Eigen::VectorXd& reference)
{
    return (x - reference).norm() / reference.norm();
}

std::string figure_label(const std::string& solver)
{
    static const std::map<std::string, std::string> direct{{"ours-cholesky", "ours Cholesky (direct)"},
                                                           {"eigen-llt", "Eigen LLT (direct)"},
                                                           {"cholmod", "CHOLMOD (direct)"}};
    const auto found = direct.find(solver);
    return found == direct.end() ? solver : found->second;
}

OurMethod make_method(const std::string& name, const sparse::CsrMatrix& csr)
{
    OurMethod method;
    method.name = name;
    Timer timer;
    if (name == "PCG-Jacobi")
        method.preconditioner = std::make_unique<JacobiPreconditioner>(diagonal(csr));
    else if (name == "PCG-IC0")
        method.preconditioner = std::make_unique<IncompleteCholesky>(csr);
    method.setup_seconds = timer.seconds();
    return method;
}

CgResult run_method(const LinearOperator& A, const OurMethod& method, const Eigen::VectorXd& b, Eigen::VectorXd& x,
                    const CgSettings& settings)
{
    return method.preconditioner ? preconditioned_conjugate_gradient(A, *method.preconditioner, b, x, settings)
                                 : conjugate_gradient(A, b, x, settings);
}

}  // namespace fem::cg::study
