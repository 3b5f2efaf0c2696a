#pragma once
// Chapter 12: a hyperelastic body as a chapter 10 force model — per tet the energy V ψ(F), the
// forces −V Bᵀ vec(P) and the Hessian V Bᵀ (∂P/∂F) B, the Hessian made positive semi-definite on
// request and assembled into chapter 06's fixed pattern. docs/12_hyperelastic_newton.md#the-force-model

#include "12_hyperelastic_newton/materials.hpp"

#include "10_linear_dynamics/body.hpp"

#include "04_tet_jacobians/tet_jacobians.hpp"
#include "06_assembly/assembly.hpp"

#include <Eigen/Core>

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace fem::hyper {

using Vector12d = Eigen::Matrix<double, 12, 1>;

/// One tet's elastic energy V ψ(F) [J] (V its rest volume, F = I + H, H = mat(B u_e) its
/// displacement gradient).
double element_energy(const Material& material, double volume, const Eigen::Matrix3d& H);

/// One tet's internal forces f_e = −V Bᵀ vec(P(F)) (12, vertex-major; B: chapter 04's 9×12).
/// docs/12_hyperelastic_newton.md#element-forces-and-hessians
Vector12d element_forces(const Material& material, double volume, const tet::Jacobian& B, const Eigen::Matrix3d& H);

/// One tet's Hessian V Bᵀ (∂P/∂F) B (12×12), with ∂P/∂F first made positive semi-definite when
/// projection is set (then the element Hessian is too: Bᵀ A B is PSD for PSD A).
/// docs/12_hyperelastic_newton.md#definiteness
Matrix12d element_hessian(const Material& material, double volume, const tet::Jacobian& B, const Eigen::Matrix3d& H,
                          std::optional<Projection> projection);

/// A hyperelastic body: U(u) = Σ V_t ψ(F_t), f = −∂U/∂u, K = ∂²U/∂u² (the true Hessian, possibly
/// indefinite) and a definite stand-in with every element Hessian projected; either is written into
/// chapter 06's fixed CSR pattern every call.
class HyperelasticElasticity final : public dynamics::ForceModel {
public:
    /// B and V of every rest tet and the pattern; projection: how definite_stiffness makes each
    /// element Hessian PSD. fem::Error for a zero-volume rest tet or bad indices.
    HyperelasticElasticity(const TetMesh& mesh, std::unique_ptr<Material> material,
                           Projection projection = Projection::clamp);

    std::string name() const override { return material_->name(); }
    /// U(u) and f(u). fem::Error naming the first tet where the material is undefined (an
    /// inverted tet under neo-Hookean) or if u has not 3n entries.
    double evaluate(const Eigen::VectorXd& u, Eigen::VectorXd& forces) override;
    /// U(u) alone: +∞ if any tet is where the material is undefined (the line search's test).
    double energy(const Eigen::VectorXd& u) override;
    /// The true Hessian K(u) (3n×3n).
    const dynamics::SparseMatrix& stiffness(const Eigen::VectorXd& u) override;
    /// Σ of the element Hessians projected to PSD (3n×3n, PSD).
    const dynamics::SparseMatrix& definite_stiffness(const Eigen::VectorXd& u) override;
    bool constant_stiffness() const override { return false; }
    /// von Mises of the Cauchy stress σ = P Fᵀ / J per tet (0 for a tet with J ≤ 0).
    Eigen::VectorXd von_mises_stress(const Eigen::VectorXd& u) const override;

    const Material& material() const { return *material_; }
    /// The smallest det F over the tets at u: below 0, some tet is inverted.
    double smallest_volume_ratio(const Eigen::VectorXd& u) const;

private:
    /// H = ∇u = Σᵢ uᵢ ∇φᵢᵀ of tet t from the displacements (#V×3): F − I without its round-off.
    Eigen::Matrix3d displacement_gradient(const MatrixX3d& displacement, Eigen::Index t) const;
    MatrixX3d displacement_rows(const Eigen::VectorXd& u) const;
    /// K(u) assembled with every element Hessian projected (when projection is set) or not.
    const dynamics::SparseMatrix& assemble_hessian(const Eigen::VectorXd& u, std::optional<Projection> projection);

    TetMesh mesh_;
    std::unique_ptr<Material> material_;
    Projection projection_;
    std::vector<tet::Jacobian> B_;
    std::vector<tet::ShapeGradients> gradients_;
    Eigen::VectorXd volumes_;
    assembly::AssemblyPattern pattern_;
    dynamics::SparseMatrix K_;
    /// One tet's share of evaluate(): V ψ(F) and f_e.
    struct ElementForces {
        double energy = 0.0;
        Vector12d forces;
    };
    // The slots of the parallel loops (common/parallel.hpp), added up in tet order after them.
    std::vector<double> element_energies_;
    std::vector<ElementForces> element_forces_;
    std::vector<Matrix12d> element_matrices_;
};

}  // namespace fem::hyper
