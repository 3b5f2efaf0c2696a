#include "11_corotational/studies.hpp"
namespace fem::corot::study {
void rotation_study(const RunContext&, const Settings&) {}
}
