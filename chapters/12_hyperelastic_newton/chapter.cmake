# The executable's studies, one file each (studies.hpp); not part of the chapter's library.
target_sources(${exe} PRIVATE
  ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_materials.cpp ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_newton.cpp
  ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_swing.cpp ${FEM_ROOT}/chapters/12_hyperelastic_newton/study_cost.cpp)

# The plain route the cost study compares with (plain_routes.hpp, which uses chapter 11's plain
# Cholesky), in the executable and in the tests that hold it to our step.
set(plain_route_sources ${FEM_ROOT}/chapters/12_hyperelastic_newton/plain_routes.cpp
                        ${FEM_ROOT}/chapters/11_corotational/plain_routes.cpp)
target_sources(${exe} PRIVATE ${plain_route_sources})
if(test_exe)
  target_sources(${test_exe}_objects PRIVATE ${plain_route_sources})
endif()
