# Chapter 10 finds the modes of large meshes with Spectra's Lanczos solvers (header-only, Debian's
# libspectra-dev, installed by tools/setup.sh). Included by fem_add_chapter, where ${lib} names the
# chapter's library.
find_package(spectra 1.0 REQUIRED CONFIG PATHS /usr/share/spectra/cmake)
foreach(target IN LISTS chapter_libraries)
  target_link_libraries(${target} PRIVATE Spectra::Spectra)
endforeach()

