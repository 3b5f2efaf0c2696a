# ctest ch15_ccd_queries: --ccd-queries alone (only the CCD study runs) on the project's copy of the
# CCD benchmark's unit-test queries, its table against tests/15_body_contact/expected_ccd_queries.
# Labelled ch15_slow: the sanitizer stage leaves it out (34 s there); its unit test "inclusion CCD: no
# false negative on the benchmark's … queries" runs the same queries under the sanitizers.
if(FEM_BUILD_TESTS AND program_checked)  # program_checked: fem_add_chapter (FEM_PROGRAMS)
  set(ccd_data ${FEM_ROOT}/data/ccd-unit-tests)
  add_test(NAME ch15_ccd_queries
           COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_run.py --exe $<TARGET_FILE:${exe}>
                   --expected ${FEM_ROOT}/tests/15_body_contact/expected_ccd_queries
                   --out ${CMAKE_BINARY_DIR}/check_runs/15_body_contact_ccd_queries --
                   --ccd-queries ${ccd_data}/vertex-face/data_0_0.csv ${ccd_data}/vertex-face/data_0_1.csv
                   ${ccd_data}/edge-edge/data_0_0.csv ${ccd_data}/edge-edge/data_0_1.csv)
  set_tests_properties(ch15_ccd_queries PROPERTIES LABELS "ch15;run;ch15_slow")
endif()
