# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_materials.cpp ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_newton.cpp
  ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_swing.cpp ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_cost.cpp)
