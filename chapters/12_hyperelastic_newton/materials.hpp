#pragma once
// Chapter 12: hyperelastic energy densities ψ(F), their first Piola–Kirchhoff stress P = ∂ψ/∂F and
// its derivative ∂P/∂F, per tet. docs/12_hyperelastic_newton.md
//
// Orderings as in chapter 04: vec(F) is ROW-MAJOR, vec(F)[3a + b] = F(a, b), and the 9×9 derivative
// has (∂P/∂F)(3a + b, 3c + d) = ∂P_ab / ∂F_cd. With B the 9×12 of chapter 04 (vec(F) = B q_e), one
// tet of rest volume V has the energy V ψ(F), the forces f_e = −V Bᵀ vec(P) and the Hessian
// V Bᵀ (∂P/∂F) B (12×12). Every material is parametrised by the Lamé λ, μ of chapter 05 and agrees
// with linear elasticity (chapter 05) for small strains.
//
// The functions take the displacement gradient H = ∇u = F − I, not F: near rest ψ and P are small
// differences of terms of size μ (tr(FᵀF) − 3, J − 1, F − J F⁻ᵀ), and written in H those differences
// are exact (tr(FᵀF) − 3 = 2 tr H + ‖H‖², J − 1 = tr H + ½(tr²H − tr H²) + det H). Computed from F,
// they carry a round-off of ε μ that swamps the stress of a small strain and stalls Newton when a
// body comes to rest (docs: round-off near rest). ∂/∂F = ∂/∂H.

#include "05_strain_stress/strain_stress.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace fem::hyper {

using Matrix9d = Eigen::Matrix<double, 9, 9>;
using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;

/// vec(F), row-major (9): vec[3a + b] = F(a, b).
Vector9d flatten(const Eigen::Matrix3d& F);

/// How a symmetric matrix is made positive semi-definite (docs/12_hyperelastic_newton.md#definiteness).
enum class Projection {
    clamp,     ///< negative eigenvalues set to 0
    absolute,  ///< negative eigenvalues replaced by their absolute values
};

/// Where the eigensystem of ∂P/∂F comes from when it is projected
/// (docs/12_hyperelastic_newton.md#the-analytic-eigensystem).
enum class Eigensolver {
    numerical,  ///< Eigen's iterative solver on the 9×9 (project_to_psd<9>): any material
    analytic,   ///< closed form in F's singular values (stable_neo_hookean_eigensystem)
};

/// An energy density ψ(F) [J/m³] with its stress and stress derivative.
/// docs/12_hyperelastic_newton.md#energy-densities
class Material {
public:
    explicit Material(const elastic::Lame& lame) : lame_(lame) {}
    virtual ~Material() = default;
    virtual std::string name() const = 0;
    /// Whether ψ, P and ∂P/∂F are defined for det F ≤ 0 (an inverted or flat element).
    virtual bool defined_when_inverted() const = 0;
    /// ψ(F) at F = I + H. +∞ where the material is undefined (det F ≤ 0 for neo-Hookean), so that a
    /// line search rejects the step. fem::Error for a non-finite H.
    virtual double energy_density(const Eigen::Matrix3d& H) const = 0;
    /// P = ∂ψ/∂F (3×3) at F = I + H. fem::Error where the material is undefined.
    virtual Eigen::Matrix3d first_piola(const Eigen::Matrix3d& H) const = 0;
    /// ∂P/∂F (9×9, row-major vec on both sides) at F = I + H. fem::Error where the material is undefined.
    virtual Matrix9d piola_derivative(const Eigen::Matrix3d& H) const = 0;
    /// ∂P/∂F made positive semi-definite by `projection` (docs/12_hyperelastic_newton.md#definiteness):
    /// here project_to_psd<9>(piola_derivative(H)); a material with a closed-form eigensystem of
    /// ∂P/∂F rebuilds it from that instead. fem::Error where the material is undefined.
    virtual Matrix9d projected_piola_derivative(const Eigen::Matrix3d& H, Projection projection) const;
    const elastic::Lame& lame() const { return lame_; }

private:
    elastic::Lame lame_;
};

/// St. Venant–Kirchhoff: ψ = μ E:E + (λ/2) tr(E)², E = ½(FᵀF − I) (chapter 05's Green strain);
/// P = F S with S = 2μE + λ tr(E) I; ∂P_ab/∂F_cd = δ_ac S_db + μ (F_ad F_cb + (FFᵀ)_ac δ_bd) + λ F_ab F_cd.
/// Defined for every F, but it softens under compression and offers no resistance at all to a
/// tet flattened to zero volume. docs/12_hyperelastic_newton.md#st-venantkirchhoff
class StVenantKirchhoff final : public Material {
public:
    using Material::Material;
    std::string name() const override { return "stvk"; }
    bool defined_when_inverted() const override { return true; }
    double energy_density(const Eigen::Matrix3d& H) const override;
    Eigen::Matrix3d first_piola(const Eigen::Matrix3d& H) const override;
    Matrix9d piola_derivative(const Eigen::Matrix3d& H) const override;
};

/// Neo-Hookean: ψ = (μ/2)(tr(FᵀF) − 3) − μ ln J + (λ/2)(ln J)², J = det F;
/// P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ; ∂P_ab/∂F_cd = μ δ_ac δ_bd + (μ − λ ln J) G_ad G_cb + λ G_ab G_cd
/// with G = F⁻ᵀ. Undefined for J ≤ 0 (ψ = +∞ there). docs/12_hyperelastic_newton.md#neo-hookean
class NeoHookean final : public Material {
public:
    using Material::Material;
    std::string name() const override { return "neo-hookean"; }
    bool defined_when_inverted() const override { return false; }
    double energy_density(const Eigen::Matrix3d& H) const override;
    Eigen::Matrix3d first_piola(const Eigen::Matrix3d& H) const override;
    Matrix9d piola_derivative(const Eigen::Matrix3d& H) const override;
};

/// The change δP of neo-Hookean's first Piola stress for a change δF of F (a derivation exercise):
/// with G = F⁻ᵀ and J = det F,
///     δP = μ δF + (μ − λ ln J) G δFᵀ G + λ (G:δF) G,
/// the directional derivative of P = μ(F − F⁻ᵀ) + λ ln J F⁻ᵀ along δF (what
/// NeoHookean::piola_derivative gives as a 9×9 matrix). fem::Error for a non-finite F or δF, or
/// det F ≤ 0. docs/12_hyperelastic_newton.md#neo-hookean
Eigen::Matrix3d neo_hookean_stress_change(const elastic::Lame& lame, const Eigen::Matrix3d& F,
                                          const Eigen::Matrix3d& dF);

/// Stable neo-Hookean, the course's log-free variant of Smith, de Goes, Kim 2018 (not the paper's
/// energy, which is PaperStableNeoHookean):
/// ψ = (μ/2)(tr(FᵀF) − 3) − μ(J − 1) + (λ̂/2)(J − 1)², λ̂ = λ + μ (which makes it agree with linear
/// elasticity for small strains, and P(I) = 0). With the cofactor C = ∂J/∂F (C = J F⁻ᵀ when F is
/// invertible, defined for every F): P = μF + (λ̂(J − 1) − μ) C;
/// ∂P_ab/∂F_cd = μ δ_ac δ_bd + λ̂ C_ab C_cd + (λ̂(J − 1) − μ) ε_ack ε_bdl F_kl.
/// Defined for every F, inverted ones included: an inverted tet is pushed back.
/// docs/12_hyperelastic_newton.md#stable-neo-hookean
class StableNeoHookean final : public Material {
public:
    /// eigensolver: how projected_piola_derivative finds the eigensystem of ∂P/∂F (the closed form
    /// by default; numerical only to compare the two).
    explicit StableNeoHookean(const elastic::Lame& lame, Eigensolver eigensolver = Eigensolver::analytic)
        : Material(lame), eigensolver_(eigensolver)
    {
    }
    std::string name() const override { return "stable-neo-hookean"; }
    bool defined_when_inverted() const override { return true; }
    double energy_density(const Eigen::Matrix3d& H) const override;
    Eigen::Matrix3d first_piola(const Eigen::Matrix3d& H) const override;
    Matrix9d piola_derivative(const Eigen::Matrix3d& H) const override;
    /// Q max(Λ, 0) Qᵀ (clamp) or Q |Λ| Qᵀ (absolute) from stable_neo_hookean_eigensystem, or from
    /// project_to_psd<9> when constructed with Eigensolver::numerical.
    Matrix9d projected_piola_derivative(const Eigen::Matrix3d& H, Projection projection) const override;

private:
    Eigensolver eigensolver_;
};

/// The eigenpairs of a symmetric 9×9: ∂P/∂F = Q diag(values) Qᵀ, Q = vectors orthogonal, its
/// columns vec(Q_k) (row-major, as flatten).
struct Eigensystem9 {
    Vector9d values;
    Matrix9d vectors;
};

/// The eigensystem of the course's stable neo-Hookean ∂P/∂F = ∂²ψ/∂F² at F = I + H in closed form
/// (Smith, de Goes, Kim 2019, "Analytic eigensystems for isotropic distortion energies", ACM TOG
/// 38(1); Kim, Eberle, Dynamic Deformables, SIGGRAPH 2020 course). With the signed SVD
/// F = U Σ Vᵀ (U, V rotations, σ₂ < 0 when det F < 0), u_i, v_i their columns, w = λ̂(J − 1) − μ,
/// and (i, j, k) each of (1, 2, 0), (2, 0, 1), (0, 1, 2):
///     twist k:   Q = (u_i v_jᵀ − u_j v_iᵀ)/√2,  eigenvalue μ + w σ_k   (columns 0–2)
///     flip k:    Q = (u_i v_jᵀ + u_j v_iᵀ)/√2,  eigenvalue μ − w σ_k   (columns 3–5)
///     scaling:   Q = Σ_m z_m u_m v_mᵀ for each eigenpair (a, z) of the 3×3 ∂²ψ/∂σ²,
///                A_ii = μ + λ̂ (σ_j σ_k)², A_ij = λ̂ σ_i σ_j σ_k² + w σ_k   (columns 6–8).
/// No formula divides by σ_i − σ_j: repeated singular values (F = I) need no special case.
/// fem::Error for a non-finite H. docs/12_hyperelastic_newton.md#the-analytic-eigensystem
Eigensystem9 stable_neo_hookean_eigensystem(const elastic::Lame& lame, const Eigen::Matrix3d& H);

/// Stable neo-Hookean as Smith, de Goes and Kim 2018 write it (their final energy, with the log
/// term that makes it rest-stable and their Lamé reparametrisation), minus its value at rest:
/// ψ = (μ'/2)(I_C − 3) − (μ'/2) ln((I_C + 1)/4) + (λ'/2)((J − α)² − (1 − α)²),  I_C = tr(FᵀF),
/// α = 1 + 3μ'/(4λ') (which makes P(I) = 0), μ' = 4μ/3, λ' = λ + 5μ/6 (which make it agree with
/// linear elasticity of λ, μ for small strains). With C = ∂J/∂F as above:
/// P = μ'(1 − 1/(I_C + 1)) F + λ'(J − α) C;
/// ∂P_ab/∂F_cd = μ'(1 − 1/(I_C + 1)) δ_ac δ_bd + 2μ'/(I_C + 1)² F_ab F_cd + λ' C_ab C_cd
///               + λ'(J − α) ε_ack ε_bdl F_kl.
/// Defined for every F (I_C + 1 ≥ 1). It differs from the course's variant by its log term, which
/// keeps the energy growing for a tet collapsed to a point (I_C → 0), and by λ' < λ̂.
/// docs/12_hyperelastic_newton.md#stable-neo-hookean
class PaperStableNeoHookean final : public Material {
public:
    using Material::Material;
    std::string name() const override { return "stable-neo-hookean-paper"; }
    bool defined_when_inverted() const override { return true; }
    double energy_density(const Eigen::Matrix3d& H) const override;
    Eigen::Matrix3d first_piola(const Eigen::Matrix3d& H) const override;
    Matrix9d piola_derivative(const Eigen::Matrix3d& H) const override;
};

/// The material called `name` (one of material_names()) with the Lamé parameters of Y and ν
/// (chapter 05), from the registry in materials.cpp: one line per material. fem::Error for another
/// name (the message lists the known ones) or a bad Y, ν.
/// docs/12_hyperelastic_newton.md#adding-a-material
std::unique_ptr<Material> make_material(std::string_view name, double youngs_modulus, double poisson_ratio);

/// The names make_material accepts, in the registry's order: "stvk", "neo-hookean",
/// "stable-neo-hookean" (the course's variant), "stable-neo-hookean-paper".
std::vector<std::string> material_names();

/// What a material is called, beside make_material's name: in words, as the figures' legends write
/// it (e.g. "St. Venant-Kirchhoff"); its label, as a frame's caption writes it (short, e.g. "StVK");
/// and whether the scenes' model comparison runs it (false for a variant of one it runs already).
/// docs/12_hyperelastic_newton.md#adding-a-material
struct MaterialNames {
    std::string name, in_words, label;
    bool compared = true;
};

/// Every registered material's names (MaterialNames), in the registry's order (material_names()).
std::vector<MaterialNames> material_descriptions();

/// The cofactor matrix C = ∂(det F)/∂F (3×3): its rows are cross products of F's rows, so it is
/// defined for every F and equals det F · F⁻ᵀ when F is invertible.
Eigen::Matrix3d cofactor(const Eigen::Matrix3d& F);

/// det(I + H) − 1 = tr H + ½(tr²H − tr(H²)) + det H, without the cancellation of det F − 1.
double volume_change(const Eigen::Matrix3d& H);

/// cofactor(I + H) − I = tr H · I − Hᵀ + cofactor(H), without the cancellation.
Eigen::Matrix3d cofactor_change(const Eigen::Matrix3d& H);

/// The nearest positive semi-definite matrix by an eigen-decomposition of the symmetric part of
/// A = Q Λ Qᵀ: Q max(Λ, 0) Qᵀ (clamp) or Q |Λ| Qᵀ (absolute). 3×3 (chapter 14's vertex blocks), 6×6
/// (its edge pairs), 9×9 or 12×12.
template <int N>
Eigen::Matrix<double, N, N> project_to_psd(const Eigen::Matrix<double, N, N>& A, Projection projection);

}  // namespace fem::hyper
