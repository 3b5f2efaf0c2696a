#pragma once
// Chapter 13: a fine render surface carried by a coarse tet mesh (notes 001, "Skinning").
// docs/13_skinning.md
//
// Simulate a coarse tet mesh, render a fine triangle surface. Each surface vertex X_s lies in some
// coarse tet t with rest corners X₀…X₃; its barycentric weights in that tet,
//     (φ₁, φ₂, φ₃) = T⁻¹ (X_s − X₀),   φ₀ = 1 − φ₁ − φ₂ − φ₃,   T = [X₁−X₀ | X₂−X₀ | X₃−X₀],
// are computed once, at rest. The deformed surface is then the same weights of the deformed corners,
//     x_s = Σᵢ φᵢ x_{t,i},      all vertices at once:  x_surface = W Q,
// with W the sparse #V_skin × #V_sim matrix holding the four weights of row s in the columns of
// tet t's corners, and Q the #V_sim × 3 rows of the coarse positions (chapter 07's CSR, one
// product per frame for the three coordinates together).
//
// The notes assume every surface vertex lies inside the coarse mesh. Real meshes do not oblige:
// a vertex on the coarse boundary is outside by round-off, a coarse mesh of a decimated surface
// cuts corners. The rule here (docs/13_skinning.md#points-outside): a vertex that no tet contains
// to within the tolerance takes the tet nearest to it (Euclidean distance to the tet's closest
// point), and its barycentric weights in that tet are extrapolated (some are negative; they still
// sum to 1 and reproduce X_s exactly, so affine motions are still carried exactly). Beyond
// max_outside_distance × (that tet's longest edge) the vertex is an fem::Error naming it.
//
// The tolerance is relative, never an absolute length: a point is in tet t when every φᵢ ≥ −tol,
// and −φᵢ is the point's distance beyond face i as a fraction of the tet's height over that face.

#include "07_sparse_storage/sparse_formats.hpp"

#include "common/mesh.hpp"
#include "common/vtk_io.hpp"

#include <Eigen/Core>

#include <memory>
#include <string>
#include <vector>

namespace fem::skin {

// --- Barycentric weights ---------------------------------------------------------------------

/// The barycentric map of every tet of a mesh, prepared once: X₀ and T⁻¹ per tet, so that the
/// weights of a point cost one 3×3 product (chapter 04's shape_functions solves a system each call).
/// docs/13_skinning.md#barycentric-weights
class BarycentricFrames {
public:
    /// T⁻¹ of every tet, its bounding box and longest edge. The mesh is checked first
    /// (fem::validate: at least one tet, finite coordinates, indices in range, no flat or inverted
    /// tet — each error names the tet and what is allowed); `what` names the mesh in messages.
    explicit BarycentricFrames(const TetMesh& mesh, const std::string& what = "coarse mesh");

    /// φ = (1 − Σ φ₁…₃, T⁻¹ (p − X₀)) of point p in tet t (4 entries, summing to 1; all in [0, 1]
    /// exactly when p is in the tet; outside, extrapolated). t is not range-checked (tets() > t ≥ 0).
    Eigen::Vector4d weights(int t, const Eigen::Vector3d& p) const;

    Eigen::Index tets() const { return static_cast<Eigen::Index>(inverse_.size()); }
    const TetMesh& mesh() const { return mesh_; }
    /// The longest edge of tet t: the length that turns a relative tolerance into a distance.
    double longest_edge(int t) const { return longest_edge_[t]; }
    /// The axis-aligned bounding box of tet t, rows min and max (2×3).
    Eigen::Matrix<double, 2, 3> box(int t) const;

private:
    TetMesh mesh_;
    std::vector<Eigen::Matrix3d> inverse_;   // T⁻¹ per tet
    MatrixX3d origin_;                       // X₀ per tet (#T×3)
    Eigen::VectorXd longest_edge_;
};

// --- Point location ----------------------------------------------------------------------------

/// Where a point lies: the containing tet and the point's weights in it.
struct Location {
    int tet = -1;                                  ///< -1: no tet contains the point
    Eigen::Vector4d phi = Eigen::Vector4d::Zero(); ///< barycentric weights in `tet`
};

/// The three ways to find the tet of a point, compared in the chapter's executable.
enum class LocateMethod {
    brute_force,  ///< test every tet: O(#T) a point, no set-up
    grid,         ///< a uniform grid of cells listing the tets whose (padded) box meets them
    tree,         ///< an AABB tree over the tets' (padded) boxes
};

/// fem::Error naming `where` unless 0 ≤ tolerance < 0.5 (a fraction of a tet's heights): the check of
/// every locator and of build_skin.
void require_location_tolerance(double tolerance, const char* where);

/// "brute-force", "grid", "tree".
std::string method_name(LocateMethod method);
/// The method called `name` (as method_name writes it); fem::Error listing the names otherwise.
LocateMethod parse_method(const std::string& name);

/// Every method returns the same tet: the LOWEST-NUMBERED tet with min φᵢ ≥ −tolerance, or -1. A
/// point on a shared face, edge or vertex lies in several tets; this rule picks one of them
/// independently of the search (the grid and the tree test all their candidates and keep the lowest
/// number). Each tet's box is padded by 3 × tolerance × its longest edge: the points the tolerance
/// admits form the tet scaled by 1 + 4 × tolerance about its centroid, which reaches that far beyond
/// a corner, so the box tests never miss one. docs/13_skinning.md#point-location
class PointLocator {
public:
    virtual ~PointLocator() = default;
    virtual LocateMethod method() const = 0;
    /// The tet and weights of p, by the rule above. p must be finite (checked by build_skin).
    virtual Location locate(const Eigen::Vector3d& p) const = 0;
};

/// The lowest-numbered tet containing p, by testing every tet in order (the reference; chapter 04's
/// locate_point does the same with a linear solve per tet). docs/13_skinning.md#point-location
Location locate_brute_force(const BarycentricFrames& frames, const Eigen::Vector3d& p, double tolerance);

/// A uniform grid over the mesh's bounding box with about `cells_per_tet` × #T cells (cubes as
/// near as the box allows); cell c lists every tet whose padded box meets it (CSR-like: offsets and
/// tet numbers, ascending). A query visits the one cell of p. docs/13_skinning.md#a-uniform-grid
class UniformGrid final : public PointLocator {
public:
    /// fem::Error for a tolerance outside [0, 0.5) or cells_per_tet ≤ 0. frames must outlive the grid.
    UniformGrid(const BarycentricFrames& frames, double tolerance, double cells_per_tet = 1.0);
    LocateMethod method() const override { return LocateMethod::grid; }
    Location locate(const Eigen::Vector3d& p) const override;
    /// Cells along x, y, z.
    const Eigen::Vector3i& dims() const { return dims_; }
    /// The mean number of tets a cell lists.
    double mean_tets_per_cell() const;

private:
    /// The cell (i, j, k) holding p, clamped to the grid.
    Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;

    const BarycentricFrames& frames_;
    double tolerance_;
    Eigen::Vector3d origin_, cell_size_;
    Eigen::Vector3i dims_;
    std::vector<int> offsets_, tets_;   // tets of cell c: tets_[offsets_[c] … offsets_[c+1]−1]
};

/// A node of a bounding-volume hierarchy: its box, and either two children or a range of items.
struct BoxNode {
    Eigen::Vector3d low, high;
    int left = -1, right = -1;   ///< children (-1 for a leaf)
    int first = 0, count = 0;    ///< a leaf's items: items[first … first + count − 1]
};

/// A bounding-volume hierarchy over any boxes: nodes[0] is the root, and the leaves' ranges index
/// items, the box numbers in tree order.
struct BoxHierarchy {
    std::vector<BoxNode> nodes;
    std::vector<int> items;
};

/// The hierarchy of boxes (each 2×3: rows min and max): a node's box holds its items' boxes, split
/// at the median of the box centres along the node box's longest axis until a leaf holds at most
/// leaf_size (≥ 1) boxes. The tree of AabbTree (tets) and of chapter 14's mesh obstacle (triangles).
/// docs/13_skinning.md#an-aabb-tree
BoxHierarchy box_hierarchy(const std::vector<Eigen::Matrix<double, 2, 3>>& boxes, int leaf_size);

/// The items of tree (built over boxes) whose boxes meet the box [low, high] (touching counts),
/// found by descending into every node whose box meets it; in the tree's order.
std::vector<int> boxes_meeting(const BoxHierarchy& tree, const std::vector<Eigen::Matrix<double, 2, 3>>& boxes,
                               const Eigen::Vector3d& low, const Eigen::Vector3d& high);

/// A bounding-volume hierarchy: a binary tree of axis-aligned boxes, each node's box holding its
/// tets' padded boxes, split at the median of the tet centroids along the box's longest axis until
/// a leaf holds at most `leaf_size` tets (box_hierarchy). A query descends into every child whose
/// box holds p. docs/13_skinning.md#an-aabb-tree
class AabbTree final : public PointLocator {
public:
    /// fem::Error for a tolerance outside [0, 0.5) or leaf_size < 1. frames must outlive the tree.
    AabbTree(const BarycentricFrames& frames, double tolerance, int leaf_size = 4);
    LocateMethod method() const override { return LocateMethod::tree; }
    Location locate(const Eigen::Vector3d& p) const override;
    /// The number of nodes and the depth of the deepest leaf.
    int nodes() const { return static_cast<int>(nodes_.size()); }
    int depth() const;

    /// A node: its box, and either two children or a range of tets_ (first, count).
    using Node = BoxNode;

private:
    const BarycentricFrames& frames_;
    double tolerance_;
    std::vector<Eigen::Matrix<double, 2, 3>> boxes_;  // padded box per tet
    std::vector<Node> nodes_;
    std::vector<int> tets_;
};

/// The brute-force search as a PointLocator (what the executable times beside the other two).
class BruteForce final : public PointLocator {
public:
    /// fem::Error for a tolerance outside [0, 0.5). frames must outlive the locator.
    BruteForce(const BarycentricFrames& frames, double tolerance);
    LocateMethod method() const override { return LocateMethod::brute_force; }
    Location locate(const Eigen::Vector3d& p) const override { return locate_brute_force(frames_, p, tolerance_); }

private:
    const BarycentricFrames& frames_;
    double tolerance_;
};

/// A locator of the given method over frames (which must outlive it).
std::unique_ptr<PointLocator> make_locator(LocateMethod method, const BarycentricFrames& frames, double tolerance);

// --- Points outside ------------------------------------------------------------------------------

/// The closest point to p on the triangle (a, b, c) (Ericson, Real-Time Collision Detection, §5.1.5:
/// the Voronoi region of p among the corners, edges and face). Exact for any non-degenerate triangle.
/// docs/13_skinning.md#points-outside
Eigen::Vector3d closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                          const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// The boundary of a tet mesh: the faces that belong to one tet only, each with that tet, oriented
/// outwards (#faces × 3 vertex indices, and the owning tet of each).
struct Boundary {
    MatrixX3i faces;
    std::vector<int> tet;
};
/// The boundary faces of mesh, in the order of their tets (and the faces within a tet: the face
/// opposite corner 0, 1, 2, 3). docs/13_skinning.md#points-outside
Boundary boundary_faces(const TetMesh& mesh);

/// The tet nearest to p and the distance: for a point outside the mesh the nearest point of the
/// mesh lies on a boundary face, so the nearest boundary face (lowest number on a tie) gives both.
struct Nearest {
    int tet = -1;
    double distance = 0.0;
};
/// The nearest boundary face to p, by testing every face whose bounding box is nearer than the
/// nearest face found so far. docs/13_skinning.md#points-outside
Nearest nearest_boundary_tet(const TetMesh& mesh, const Boundary& boundary, const Eigen::Vector3d& p);

// --- The skin ----------------------------------------------------------------------------------

/// How build_skin locates the surface vertices and what it does with those outside.
struct SkinOptions {
    LocateMethod method = LocateMethod::tree;
    /// A vertex is in tet t when every φᵢ ≥ −tolerance (relative: a fraction of the tet's heights).
    double tolerance = 1e-9;
    /// A vertex outside the mesh farther than this × the longest edge of its nearest tet is an
    /// fem::Error naming it (its weights would extrapolate too far to be trusted).
    double max_outside_distance = 0.5;
};

/// A surface vertex that no tet contains, carried by the outside rule.
struct OutsidePoint {
    int vertex = -1;              ///< the surface vertex
    int tet = -1;                 ///< its nearest tet, whose weights it extrapolates
    double distance = 0.0;        ///< its distance to the coarse mesh (the mesh's units)
    double relative_distance = 0.0;  ///< distance / (the tet's longest edge)
};

/// A fine surface bound to a coarse tet mesh: W (#V_skin × #V_sim, four weights a row, CSR) and
/// what the binding found. docs/13_skinning.md#the-skinning-matrix
struct Skin {
    TriMesh surface;                  ///< the fine surface at rest (V: #V_skin × 3)
    sparse::CsrMatrix W;              ///< x_surface = W Q
    std::vector<int> tet;             ///< the tet of every surface vertex (#V_skin)
    std::vector<OutsidePoint> outside;  ///< the vertices placed by the outside rule, by vertex
    double largest_outside_distance() const;  ///< 0 when none is outside
};

/// W from the tets and weights of the surface vertices: row s holds tet[s]'s four corners (columns,
/// ascending) with the weights phi.row(s) (#V_skin × 4), built as triplets and converted to CSR
/// (chapter 07). cols = the number of coarse vertices. docs/13_skinning.md#the-skinning-matrix
sparse::CsrMatrix skinning_matrix(const TetMesh& coarse, const std::vector<int>& tet,
                                  const Eigen::Matrix<double, Eigen::Dynamic, 4, Eigen::RowMajor>& phi);

/// Binds surface to coarse: locates every surface vertex (options.method), applies the outside rule
/// to those no tet contains, and builds W. fem::Error for an empty surface, a surface or coarse mesh
/// that fails validation (non-finite coordinates, bad indices, a degenerate triangle; a flat or
/// inverted tet — each naming the element), a bad option, or a vertex outside beyond
/// options.max_outside_distance (naming the vertex, its position, its distance and the limit).
/// docs/13_skinning.md#the-skinning-matrix
Skin build_skin(const TetMesh& coarse, const TriMesh& surface, const SkinOptions& options = {});

/// x_surface = W Q by hand: row s of the result is Σ_k A[k] Q.row(JA[k]) over row s of W's CSR
/// (#V_skin × 3 from #V_sim × 3, the three coordinates in one pass over W). fem::Error if Q has not
/// W.cols rows. docs/13_skinning.md#the-skinned-surface
MatrixX3d skinned_positions(const sparse::CsrMatrix& W, const MatrixX3d& Q);

/// The unit normal of every vertex of a surface at positions x (#V×3): the sum of the cross products
/// (b − a) × (c − a) of its triangles (area-weighted, as each is twice the triangle's area), made
/// unit length; a vertex whose sum vanishes gets (0, 0, 0). Recomputed every frame: a deformed
/// surface's normals are not the rest normals moved by W. docs/13_skinning.md#normals
MatrixX3d vertex_normals(const MatrixX3i& F, const MatrixX3d& x);

/// One frame of the skinned surface for a .vtp time series (the course's convention: the points
/// are the rest positions): point fields "displacement" = W Q − X_skin and "normal" =
/// vertex_normals of the deformed surface W Q. Q: the coarse positions (#V_sim × 3). The observer a
/// simulation calls to carry its skin (docs/13_skinning.md#the-skin-in-a-simulation).
io::MeshData skin_frame(const Skin& skin, const MatrixX3d& Q);

// --- Meshes for skinning ---------------------------------------------------------------------------

/// A coarse tet mesh that encloses a closed surface: the Kuhn-split cube lattice (box_mesh) over the
/// surface's bounding box with `cells` cubes along its longest side, keeping every cube whose centre
/// lies inside the surface (winding number > ½) or that meets the bounding box of a surface triangle,
/// so that every point of every triangle lies in a kept cube. Unused lattice vertices are dropped.
/// fem::Error for cells < 1 or a surface that fails validation. docs/13_skinning.md#the-coarse-mesh
TetMesh enclosing_lattice(const TriMesh& surface, int cells);

/// The generalized winding number of a closed surface at p (Jacobson et al. 2013): Σ of the solid
/// angles of the triangles seen from p over 4π (Van Oosterom–Strackee): 1 inside, 0 outside.
double winding_number(const TriMesh& surface, const Eigen::Vector3d& p);

/// The surface refined `levels` times by splitting each triangle into four at its edge midpoints
/// (every new vertex lies on an old triangle: the refined surface is the same shape, with about
/// 4^levels as many vertices). docs/13_skinning.md#the-coarse-mesh
TriMesh midpoint_subdivision(const TriMesh& surface, int levels);

}  // namespace fem::skin
