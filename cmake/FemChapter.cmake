# fem_add_chapter(NN name [DEPENDS MM ...] [OWN file.cpp ...])
#
# Registers chapter NN_name, the one way a chapter enters the build:
#   fem_chNN            its library: the chapter's functions, compiled from solutions/NN_name
#                       (default) or exercises/NN_name (when NN is in FEM_EXERCISES or it is "all"),
#                       from two object libraries: fem_chNN_exercises (the files with an exercise
#                       region, a student's stubs in a build from exercises/; the target
#                       fem_exercise_files builds every chapter's) and fem_chNN_plain (the other
#                       files, compiled once and shared with the reference twin); with
#                       FEM_GRADING=ON the files with a region compile from their graded copies
#                       (below);
#   fem_chNN_own        with OWN files: those files, on top of fem_chNN (below);
#   fem_chNN_reference  what later chapters link: always the reference solution, so a student
#                       working on chapter 05 keeps chapters 06+ running;
#   chNN_name           its executable in <build>/bin, from programs/NN_name/*.cpp (main.cpp, study_*.cpp);
#   test_chNN           its Catch2 tests from tests/NN_name/*.cpp (ctest label chNN); a target of
#                       its own: `cmake --build --preset student --target test_chNN`;
#                       With FEM_GRADING=ON (a build from the solutions), the files with an
#                       exercise region compile from copies with every region behind a run-time
#                       stub switch (tools/exercises.py graded; environment FEM_STUB_EXERCISE=05.2),
#                       so that test_chNN is also the binary tools/exercises.py grade runs; with the
#                       variable unset each region runs its solution. The target fem_graded_tests
#                       builds every chapter's tests;
#   chNN_quick_run      ctest: the executable in --quick mode, its files and figures against
#                       tests/NN_name/expected (label chNN, run);
#   chNN_docs           ctest: docs/NN_name.md names only functions and exercises that exist and
#                       quotes the numbers the executable prints (label chNN, docs).
#   chNN_exercise_table ctest: the same page's exercise headings and its exercise table (stub file,
#                       tagged test files, builds-on) against the code, without the executable, in
#                       a second (label chNN, docs).
#   chNN_test_target    ctest: building test_chNN alone builds no later chapter (label chNN, layout),
#                       the student's one-chapter loop (README, "A student's loop").
#   chNN_bad_options    ctest, when tests/NN_name/bad_options.txt exists: the executable refuses each
#                       bad command line of that table before it computes or writes anything
#                       (tools/check_bad_options.py says the table's form; label chNN, run).
# DEPENDS lists earlier chapters whose headers this chapter includes; a later one is an error.
# OWN lists the chapter's source files (names in solutions/NN_name) that only its own executable and
# tests call, never a later chapter: they compile into a library of their own, fem_chNN_own (linking
# fem_chNN), which later chapters do not link, so that a student's build of a later chapter does not
# compile them (chapter 10's modes.cpp and mode_solvers.cpp, Spectra's eigensolvers: 13 s of a core).

set(FEM_ALL_CHAPTERS "" CACHE INTERNAL "registered chapters")
add_custom_target(fem_tests)
add_custom_target(fem_exercise_files)
if(FEM_GRADING)
  add_custom_target(fem_graded_tests)  # every test_chNN, each a graded binary in this build
endif()

include(${CMAKE_CURRENT_LIST_DIR}/FemExercises.cmake)

# fem_discover_tests(target label [sources...]): one ctest entry per Catch2 test case of target, named
# "<label>: <test case>" and labelled <label>. Each entry runs with --warn NoTests, so an entry that
# matches no test case fails instead of passing quietly (a test name ctest cannot carry, e.g. one
# with a ';', which CMake splits into two lists items, would otherwise count as passed while
# nothing ran). tools/check_layout.py also rejects such names in the sources.
# A test that cannot run here (the live view without an X display) ends with
# WARN("SKIPPED: why") and returns: Catch2 2.13, Debian 12's, has no SKIP(), but it prints warnings
# of passing tests, and SKIP_REGULAR_EXPRESSION makes ctest report such an entry as skipped.
# Test cases tagged [slow] (many steps of a contact scene: tens of seconds under the sanitizers) are
# labelled <label>_slow instead: `ctest -L <label>` still runs them, the release stage of
# tools/test.sh runs them, and the sanitizer stage leaves them out (CMakePresets.json, asan), since
# the shorter tests of the same code run there. Optional after the label: the test sources whose
# tags are looked at (none: no test is slow). Hidden test cases ([.probe]: a measurement that prints
# a table, run by hand) are no tests of ctest's.
function(fem_discover_tests target label)
  set(has_slow OFF)
  foreach(source IN LISTS ARGN)
    file(STRINGS ${source} slow_lines REGEX "\\[slow\\]")
    if(slow_lines)
      set(has_slow ON)
    endif()
  endforeach()
  # One label only: catch_discover_tests splits a list of labels into separate properties.
  if(has_slow)
    catch_discover_tests(${target} TEST_SPEC "~[slow]~[.]" TEST_PREFIX "${label}: " EXTRA_ARGS --warn NoTests
                         PROPERTIES LABELS "${label}" SKIP_REGULAR_EXPRESSION "SKIPPED: ")
    catch_discover_tests(${target} TEST_SPEC "[slow]~[.]" TEST_PREFIX "${label}: " EXTRA_ARGS --warn NoTests
                         PROPERTIES LABELS "${label}_slow" SKIP_REGULAR_EXPRESSION "SKIPPED: ")
  else()
    catch_discover_tests(${target} TEST_PREFIX "${label}: " EXTRA_ARGS --warn NoTests
                         PROPERTIES LABELS "${label}" SKIP_REGULAR_EXPRESSION "SKIPPED: ")
  endif()
endfunction()

# fem_test_without_avx2(number test_exe): ctest chNN_without_avx2 runs the chapter's unit tests once
# more with FEM_NO_AVX2=1 (common/simd.hpp), the path of a processor without AVX2 and FMA, which an
# AVX2 machine would otherwise never run. For chapters with hand-written AVX2 kernels (their
# chapter.cmake calls it). Nothing when the tests are not built (FEM_BUILD_TESTS off: test_exe empty).
function(fem_test_without_avx2 number test_exe)
  if(FEM_BUILD_TESTS AND test_exe)
    add_test(NAME ch${number}_without_avx2 COMMAND ${test_exe} --warn NoTests)
    set_tests_properties(ch${number}_without_avx2 PROPERTIES ENVIRONMENT FEM_NO_AVX2=1 LABELS "ch${number}")
  endif()
endfunction()

# fem_reference_code(target): target is reference code a student does not step through (common/,
# a chapter's reference solution): without debug information when FEM_REFERENCE_DEBUG_INFO is OFF.
function(fem_reference_code target)
  if(NOT FEM_REFERENCE_DEBUG_INFO)
    target_compile_options(${target} PRIVATE -g0)
  endif()
endfunction()

# fem_chapter_files(out_var folder_rule file_name...): the paths of a chapter's files, for
# fem_add_chapter (reads its ${id}): each from solutions/NN_name, or with folder_rule "student" a
# file with an exercise region from exercises/NN_name (the student's copy).
function(fem_chapter_files out_var folder_rule)
  set(paths "")
  foreach(file_name IN LISTS ARGN)
    if(folder_rule STREQUAL "student" AND EXISTS ${FEM_ROOT}/exercises/${id}/${file_name})
      list(APPEND paths ${FEM_ROOT}/exercises/${id}/${file_name})
    else()
      list(APPEND paths ${FEM_ROOT}/solutions/${id}/${file_name})
    endif()
  endforeach()
  set(${out_var} ${paths} PARENT_SCOPE)
endfunction()

# fem_chapter_library(target STATIC|OBJECT sources...): a library of the chapter's code, for
# fem_add_chapter (reads its ${CH_DEPENDS} and ${plain_objects}): the sources (a static library: and
# the chapter's shared plain objects), its headers, fem_common and the reference of each chapter it
# depends on.
function(fem_chapter_library target type)
  if(type STREQUAL "OBJECT")
    add_library(${target} OBJECT ${ARGN})
  else()
    add_library(${target} STATIC ${ARGN} ${plain_objects})
  endif()
  target_include_directories(${target} PUBLIC ${FEM_ROOT}/chapters)
  target_link_libraries(${target} PUBLIC fem_common PRIVATE fem_flags)
  foreach(dep IN LISTS CH_DEPENDS)
    target_link_libraries(${target} PUBLIC fem_ch${dep}_reference)
  endforeach()
endfunction()

function(fem_add_chapter number name)
  cmake_parse_arguments(PARSE_ARGV 2 CH "" "" "DEPENDS;OWN")
  set(id ${number}_${name})
  set(lib fem_ch${number})
  foreach(dep IN LISTS CH_DEPENDS)
    if(NOT dep LESS number)
      message(FATAL_ERROR "chapter ${id} depends on chapter ${dep}: a chapter may use earlier chapters only")
    endif()
    if(NOT TARGET fem_ch${dep}_reference)
      message(FATAL_ERROR "chapter ${id} depends on chapter ${dep}, which is not registered before it")
    endif()
  endforeach()

  file(GLOB solution_sources CONFIGURE_DEPENDS ${FEM_ROOT}/solutions/${id}/*.cpp)
  if(NOT solution_sources)
    message(FATAL_ERROR "chapter ${id}: no sources in solutions/${id}")
  endif()

  set(from_exercises OFF)
  if(FEM_EXERCISES STREQUAL "all" OR number IN_LIST FEM_EXERCISES)
    set(from_exercises ON)
    message(STATUS "chapter ${number}: from exercises/ (your code; later chapters keep the reference solution)")
  endif()

  # The chapter's files in three sets:
  #   exercise_files  the files with an exercise region (exercises/ holds their stubbed copies,
  #                   tools/exercises.py generate), but the OWN ones;
  #   own_files       the OWN files (with or without a region);
  #   plain_files     the rest: compiled once, into the object library fem_chNN_plain, whose objects
  #                   every variant of the chapter's library shares (a student's, the reference),
  #                   since those files are the same in all of them.
  set(exercise_files "")
  set(own_files "")
  set(plain_files "")
  foreach(file_name IN LISTS CH_OWN)
    if(NOT EXISTS ${FEM_ROOT}/solutions/${id}/${file_name})
      message(FATAL_ERROR "chapter ${id}: OWN ${file_name} is not a file of solutions/${id}")
    endif()
  endforeach()
  foreach(src IN LISTS solution_sources)
    get_filename_component(file_name ${src} NAME)
    if(file_name IN_LIST CH_OWN)
      list(APPEND own_files ${file_name})
    elseif(EXISTS ${FEM_ROOT}/exercises/${id}/${file_name})
      list(APPEND exercise_files ${file_name})
    else()
      list(APPEND plain_files ${file_name})
    endif()
  endforeach()
  set(folder_rule solutions)
  if(from_exercises)
    set(folder_rule student)
  endif()
  # A grading build compiles the files with exercise regions (and the OWN files) once, from copies
  # generated at build time with each region behind the run-time switch fem::exercise_stubbed, so
  # that tools/exercises.py grade proves, one exercise at a time, that its tests fail on a stub,
  # without a rebuild and without a second copy of the library. Chapters built from exercises/ are
  # a student's and are not graded.
  set(graded_dir "")
  if(FEM_GRADING AND NOT from_exercises AND (exercise_files OR own_files))
    set(graded_dir ${CMAKE_BINARY_DIR}/graded/${id})
    set(graded_outputs "")
    foreach(file_name IN LISTS exercise_files own_files)
      list(APPEND graded_outputs ${graded_dir}/${file_name})
    endforeach()
    add_custom_command(
      OUTPUT ${graded_outputs}
      COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/exercises.py graded --root ${FEM_ROOT}
              --chapter ${id} --out ${graded_dir} --files ${exercise_files} ${own_files}
      DEPENDS ${solution_sources} ${FEM_ROOT}/tools/exercises.py
      COMMENT "Generating graded sources of chapter ${id}")
  endif()

  set(plain_objects "")
  if(plain_files)
    fem_chapter_files(plain_sources solutions ${plain_files})
    fem_chapter_library(${lib}_plain OBJECT ${plain_sources})
    fem_reference_code(${lib}_plain)
    fem_unity_code(${lib}_plain)
    set(plain_objects $<TARGET_OBJECTS:${lib}_plain>)
  endif()
  # The files a student edits (in a build from exercises/, the stubs) compile into an object library
  # of their own, fem_chNN_exercises: the target fem_exercise_files builds only those (the exercises
  # preset: every stub compiles; the other files are the solutions' own, compiled by any build).
  fem_chapter_files(exercise_sources ${folder_rule} ${exercise_files})
  if(graded_dir)
    list(TRANSFORM exercise_files PREPEND ${graded_dir}/ OUTPUT_VARIABLE exercise_sources)
  endif()
  set(exercise_objects "")
  if(exercise_sources)
    fem_chapter_library(${lib}_exercises OBJECT ${exercise_sources})
    set(exercise_objects $<TARGET_OBJECTS:${lib}_exercises>)
    add_dependencies(fem_exercise_files ${lib}_exercises)
  endif()
  fem_chapter_library(${lib} STATIC ${exercise_objects})
  # What the chapter's executable and tests link (`user`): fem_chNN, or fem_chNN_own on top of it;
  # `code_libraries`: the targets compiling the files a student may edit.
  set(user ${lib})
  set(code_libraries "")
  if(exercise_sources)
    set(code_libraries ${lib}_exercises)
  endif()
  if(own_files)
    set(user ${lib}_own)
    fem_chapter_files(own_sources ${folder_rule} ${own_files})
    if(graded_dir)
      list(TRANSFORM own_files PREPEND ${graded_dir}/ OUTPUT_VARIABLE own_sources)
    endif()
    add_library(${user} STATIC ${own_sources})
    target_link_libraries(${user} PUBLIC ${lib} PRIVATE fem_flags)
    list(APPEND code_libraries ${user})
    add_dependencies(fem_exercise_files ${user})
  endif()
  if(from_exercises)
    # A stub leaves its parameters and the helpers its solution used unused.
    foreach(target IN LISTS code_libraries)
      target_compile_options(${target} PRIVATE -Wno-unused-parameter -Wno-unused-variable
                             -Wno-unused-but-set-variable -Wno-unused-function)
    endforeach()
    # Later chapters keep running on the reference solution of this one: the solutions of the
    # files with exercises, and the shared plain objects.
    fem_chapter_files(reference_sources solutions ${exercise_files})
    fem_chapter_library(${lib}_reference STATIC ${reference_sources})
    fem_reference_code(${lib}_reference)
  else()
    add_library(${lib}_reference ALIAS ${lib})
    foreach(target IN LISTS code_libraries)
      fem_reference_code(${target})
    endforeach()
  endif()

  set(exe ch${number}_${name})
  # The executable: every .cpp of programs/NN_name (main.cpp and its studies, study_*.cpp, with
  # their program-only headers beside them), never a file of another chapter's programs.
  file(GLOB program_sources CONFIGURE_DEPENDS ${FEM_ROOT}/programs/${id}/*.cpp)
  if(NOT EXISTS ${FEM_ROOT}/programs/${id}/main.cpp)
    message(FATAL_ERROR "chapter ${id}: no programs/${id}/main.cpp")
  endif()
  add_executable(${exe} ${program_sources})
  fem_unity_code(${exe})
  target_link_libraries(${exe} PRIVATE ${user} fem_flags)
  # FEM_PROGRAMS (CMakeLists.txt): an executable left out is still a target, built only by name,
  # and ctest runs none of its checks.
  set(program_checked ON)
  if(NOT FEM_PROGRAMS STREQUAL "all" AND NOT number IN_LIST FEM_PROGRAMS)
    set(program_checked OFF)
    set_target_properties(${exe} PROPERTIES EXCLUDE_FROM_ALL ON)
  endif()

  if(FEM_BUILD_TESTS)
    file(GLOB test_sources CONFIGURE_DEPENDS ${FEM_ROOT}/tests/${id}/*.cpp)
    if(NOT test_sources)
      message(FATAL_ERROR "chapter ${id}: no tests in tests/${id}")
    endif()
    set(test_exe test_ch${number})
    # The test sources are compiled as an object library that sees the chapters' headers, not a
    # chapter library, so that the test executable links the chapter's library of this build.
    add_library(${test_exe}_objects OBJECT ${test_sources})
    target_include_directories(${test_exe}_objects PRIVATE ${FEM_ROOT}/chapters)
    target_link_libraries(${test_exe}_objects PRIVATE fem_test_main fem_flags)
    target_compile_definitions(${test_exe}_objects PRIVATE FEM_TEST_OUTPUT_DIR="${CMAKE_BINARY_DIR}/test_output/${id}")
    fem_test_sources(${test_exe}_objects)  # tests/common/CMakeLists.txt
    add_executable(${test_exe})
    target_link_libraries(${test_exe} PRIVATE ${test_exe}_objects ${user} fem_test_main fem_flags)
    fem_discover_tests(${test_exe} "ch${number}" ${test_sources})
    add_dependencies(fem_tests ${test_exe})
    if(FEM_GRADING)
      add_dependencies(fem_graded_tests ${test_exe})
    endif()
  endif()
  if(FEM_BUILD_TESTS AND program_checked)
    add_test(NAME ch${number}_quick_run
             COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_run.py
                     --exe $<TARGET_FILE:${exe}> --expected ${FEM_ROOT}/tests/${id}/expected
                     --out ${CMAKE_BINARY_DIR}/check_runs/${id})
    # COST: ctest -j starts the costliest tests first (before it has timed a run of its own), so
    # that the docs checks (whole runs of the executable, up to minutes) do not start last and keep
    # one core busy alone at the end; then the quick runs, then the unit tests.
    set_tests_properties(ch${number}_quick_run PROPERTIES LABELS "ch${number};run" COST 10)
    add_test(NAME ch${number}_docs
             COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_docs.py --root ${FEM_ROOT}
                     --chapter ${id} --bin ${CMAKE_BINARY_DIR}/bin
                     --out ${CMAKE_BINARY_DIR}/check_docs/${id})
    set_tests_properties(ch${number}_docs PROPERTIES LABELS "ch${number};docs" COST 100)
    add_test(NAME ch${number}_exercise_table
             COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_docs.py --root ${FEM_ROOT}
                     --chapter ${id} --exercises-only)
    set_tests_properties(ch${number}_exercise_table PROPERTIES LABELS "ch${number};docs")
    add_test(NAME ch${number}_test_target
             COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_targets.py --build ${CMAKE_BINARY_DIR}
                     --chapter ${id})
    set_tests_properties(ch${number}_test_target PROPERTIES LABELS "ch${number};layout")
    if(EXISTS ${FEM_ROOT}/tests/${id}/bad_options.txt)
      add_test(NAME ch${number}_bad_options
               COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_bad_options.py
                       --exe $<TARGET_FILE:${exe}> --table ${FEM_ROOT}/tests/${id}/bad_options.txt)
      set_tests_properties(ch${number}_bad_options PROPERTIES LABELS "ch${number};run")
    endif()
  endif()

  # A chapter's own additions to the build (e.g. an optional reference library for its
  # executable) go in programs/NN_name/chapter.cmake, included here, where ${lib}, ${exe} and
  # ${test_exe} name its targets (the test sources compile in ${test_exe}_objects: a compile
  # option or definition for them goes there) and ${chapter_libraries} lists every library built
  # from its sources: ${lib} and its object libraries ${lib}_exercises and ${lib}_plain, with OWN
  # files ${lib}_own, in a student build also the reference twin ${lib}_reference. A package the
  # chapter's code needs is linked to each of them.
  set(chapter_libraries ${lib} ${code_libraries})
  if(TARGET ${lib}_plain)
    list(APPEND chapter_libraries ${lib}_plain)
  endif()
  get_target_property(reference_aliased ${lib}_reference ALIASED_TARGET)
  if(NOT reference_aliased)
    list(APPEND chapter_libraries ${lib}_reference)
  endif()
  if(EXISTS ${FEM_ROOT}/programs/${id}/chapter.cmake)
    include(${FEM_ROOT}/programs/${id}/chapter.cmake)
  endif()

  set(FEM_ALL_CHAPTERS ${FEM_ALL_CHAPTERS} ${id} CACHE INTERNAL "registered chapters")
endfunction()
