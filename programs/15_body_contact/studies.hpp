#pragma once
// The studies of ch15_body_contact, one file each (study_*.cpp), called in order by main.cpp.
// Not part of the chapter's library: only the executable uses them.

#include "14_contact/contact_scenes.hpp"

#include "common/cli.hpp"

#include <string>
#include <vector>

namespace fem::contact::study {

/// The executable's options (main.cpp checks them before any study runs).
struct Settings {
    int mesh_queries = 20000;                               ///< random points a mesh distance is timed on
    std::vector<double> grid_spacings{0.01, 0.005, 0.0025}; ///< the sampled grids' spacings h [m]
};

/// The distance to a mesh three ways, then bowl_study.
void mesh_study(const RunContext& run, const Settings& settings);
/// A block dropped into the bowl (the mesh obstacle in use): bowl.pvd, its PNG frames, bowl_table.csv.
void bowl_study(const RunContext& run);
/// The broad phase of self-contact three ways (brute force, AABB tree, spatial hash) on two blocks
/// of k³ cells closing on each other: candidate pairs, whether they agree, time per search;
/// self_broad_phase_table.csv (study_self.cpp).
void self_contact_study(const RunContext& run);
/// Two coarse bunnies thrown at each other, with self-contact and without: per step the time in
/// the linear solves, the barrier (with its broad phase) and the collision check, the momentum's
/// drift, intersection-free or not; two_bunnies_table.csv (study_bodies.cpp). Then the contact run
/// with Newton's tolerance 10⁻³: its iterations and how far it ends from the default's;
/// two_bunnies_tolerance_table.csv. With hessian_variants (ch15_body_contact --hessian-variants; eight
/// more runs of the bunnies, minutes), the contact run again with the barrier's Hessian projected
/// otherwise or tried exact first, κ doubled or fixed, and Newton also stopped by its step's length
/// (NewtonOptions::step_tolerance): two_bunnies_hessian_table.csv.
void bodies_study(const RunContext& run, bool hessian_variants = false);
/// test_stack.cpp's three blocks settled on the floor for each d̂ and Newton tolerance: the force
/// between blocks against the weight above, the gaps against d̂, the height against the tightest
/// tolerance's, Newton iterations and time per step; stack_tolerance_table.csv (study_stack.cpp).
void stack_study(const RunContext& run);

}  // namespace fem::contact::study
