#pragma once
// The studies of ch13_skinning, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "13_skinning/skinning.hpp"

#include "10_linear_dynamics/body.hpp"
#include "10_linear_dynamics/time_integration.hpp"

#include "common/cli.hpp"

#include <memory>
#include <string>
#include <vector>

namespace fem::skin::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    std::vector<int> cells{4, 6, 8, 12, 16};           ///< lattice resolutions of the sweep (cubes along the longest side)
    int shown_cells = 8;                           ///< the lattice of the time series and PNG frames
    int levels = 3;                                ///< midpoint subdivisions of the upsampled bunny
    std::string model = "corotational";            ///< the force model of both simulations
    dynamics::Material rubber{1e5, 0.45, 1000.0};  ///< chapter 10's rubber bunny
    double duration = 1.0;                         ///< length of the push [s], a multiple of 1/60
    double max_outside = 0.5;                      ///< SkinOptions::max_outside_distance
    double seconds = 0.2;                          ///< measuring time per timed kernel [s]
};

/// The force models the simulations offer: "corotational" (chapter 11, backward Euler) and
/// "stable-neo-hookean" (chapter 12, backward Euler by Newton), both built by chapter 12's
/// make_force_model and make_integrator_for.
const std::vector<std::string>& model_names();

/// data/bunny.obj in its own units (about 9.7 tall, y up).
TriMesh bunny_surface();
/// data/bunny_coarse.node/.ele: TetGen's tets of the bunny, its surface kept exactly.
TetMesh bunny_tets();

/// The ground the bunny stands on: y = low + 0.05 (high − low), its lowest 5 % (y range of surface).
double ground_height(const TriMesh& surface);

/// A body of the rubber bunny on mesh (already in metres), standing on the ground of the bunny
/// surface (every vertex with y ≤ ground_height pinned, or the vertices `pinned` when given), with
/// the force model settings.model and the integrator that model needs (hyper::make_force_model,
/// hyper::make_integrator_for: fem::Error for an unknown name). The body keeps the returned integrator's model alive.
struct Run {
    std::unique_ptr<dynamics::Body> body;
    std::unique_ptr<dynamics::Integrator> integrator;
    Eigen::VectorXd push;  ///< the initial velocity: chapter 10's sideways push
};
Run bunny_run(const TetMesh& mesh, const TriMesh& surface, const Settings& settings,
              const std::vector<int>* pinned = nullptr);

void location_study(const RunContext& run, const Settings& settings);
void outside_study(const RunContext& run, const Settings& settings);
void simulation_study(const RunContext& run, const Settings& settings);

}  // namespace fem::skin::study
