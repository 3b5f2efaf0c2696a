// What the studies of ch10_linear_dynamics share: the beam scene, its tip, and a body's frame.
#include "studies.hpp"

#include "06_assembly/assembly.hpp"

namespace fem::dynamics::study {

}  // namespace fem::dynamics::study
