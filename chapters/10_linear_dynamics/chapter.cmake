# Chapter 10 finds the modes of large meshes with Spectra's Lanczos solvers (header-only, Debian's
# libspectra-dev, installed by tools/setup.sh). Included by fem_add_chapter, where ${lib} names the
# chapter's library.
find_package(spectra 1.0 REQUIRED CONFIG PATHS /usr/share/spectra/cmake)
foreach(target IN LISTS chapter_libraries)
  target_link_libraries(${target} PRIVATE Spectra::Spectra)
endforeach()

# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/10_linear_dynamics/study_common.cpp ${FEM_ROOT}/chapters/10_linear_dynamics/study_modes.cpp
  ${FEM_ROOT}/chapters/10_linear_dynamics/study_accuracy.cpp ${FEM_ROOT}/chapters/10_linear_dynamics/study_cost.cpp
  ${FEM_ROOT}/chapters/10_linear_dynamics/study_scenes.cpp)
