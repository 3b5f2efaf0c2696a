# The scenes capstone (docs/scenes.md): the scene file and runner library fem_scenes (its contract
# in chapters/scenes, its code and internal headers in solutions/scenes; no exercises), the
# executable bin/fem_scene (programs/scenes/main.cpp), its tests test_scenes (ctest label scenes), a
# --quick run of every gallery scene in scenes/ against its stored numbers
# (tests/scenes/expected/<scene>), and every gallery scene at full size (label full).
find_package(tomlplusplus 3 REQUIRED)  # Debian's libtomlplusplus-dev (tools/setup.sh)

file(GLOB scene_sources CONFIGURE_DEPENDS ${FEM_ROOT}/solutions/scenes/*.cpp)
add_library(fem_scenes STATIC ${scene_sources})
target_include_directories(fem_scenes PUBLIC ${FEM_ROOT}/chapters)
target_link_libraries(fem_scenes PUBLIC fem_ch16_reference fem_ch15_reference fem_ch14_reference fem_ch13_reference fem_ch12_reference fem_ch11_reference fem_ch10_reference
                      PRIVATE tomlplusplus::tomlplusplus fem_flags)
target_compile_options(fem_scenes PRIVATE ${FEM_FUZZ_FLAGS})  # the scene reader, fuzz_scene's ground
fem_reference_code(fem_scenes)
fem_unity_code(fem_scenes)

add_executable(fem_scene ${FEM_ROOT}/programs/scenes/main.cpp)
target_link_libraries(fem_scene PRIVATE fem_scenes fem_flags)

if(FEM_BUILD_TESTS)
  file(GLOB scene_test_sources CONFIGURE_DEPENDS ${FEM_ROOT}/tests/scenes/*.cpp)
  add_executable(test_scenes ${scene_test_sources})
  target_link_libraries(test_scenes PRIVATE fem_scenes fem_test_main fem_flags
                        VTK::CommonCore VTK::CommonDataModel VTK::IOImage  # test_frames.cpp reads the PNG frames
                        X11::X11 X11::Xtst)  # test_live_view.cpp drives the live view's keys and mouse
  target_compile_definitions(test_scenes PRIVATE FEM_TEST_OUTPUT_DIR="${CMAKE_BINARY_DIR}/test_output/scenes"
                             FEM_SCENES_DIR="${FEM_ROOT}/scenes" FEM_SCENE_EXE="$<TARGET_FILE:fem_scene>"
                             FEM_SCENE_BAD_DIR="${FEM_ROOT}/tests/scenes/bad_scenes")
  add_dependencies(test_scenes fem_scene)
  fem_test_sources(test_scenes)
  fem_discover_tests(test_scenes "scenes" ${scene_test_sources})
  add_dependencies(fem_tests test_scenes)

  # Every gallery scene in --quick mode against its stored numbers (tools/check_run.py).
  file(GLOB gallery CONFIGURE_DEPENDS ${FEM_ROOT}/scenes/*.toml)
  # Quick runs too slow for the sanitizer stage (label scenes_slow, which it leaves out; the release
  # stage runs them): bar_coil, 95 s there, whose self-contact code test_ch15 runs under the sanitizers.
  set(scenes_slow_under_sanitizers bar_coil)
  foreach(scene_file IN LISTS gallery)
    get_filename_component(scene ${scene_file} NAME_WE)
    add_test(NAME scenes_quick_run_${scene}
             COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_run.py
                     --exe $<TARGET_FILE:fem_scene> --expected ${FEM_ROOT}/tests/scenes/expected/${scene}
                     --out ${CMAKE_BINARY_DIR}/check_runs/scenes/${scene} -- ${scene_file} --no-progress)
    set(labels "scenes;run")
    if(scene IN_LIST scenes_slow_under_sanitizers)
      list(APPEND labels scenes_slow)
    endif()
    set_tests_properties(scenes_quick_run_${scene} PROPERTIES LABELS "${labels}" COST 10)  # as chNN_quick_run
    # … and at full size, as tools/run_course.sh runs it (figures off): the run command cannot break
    # unnoticed. Label full: the release stage runs it, the sanitizer stage leaves it out (too slow there).
    add_test(NAME scenes_full_${scene}
             COMMAND $<TARGET_FILE:fem_scene> ${scene_file} --no-figures --no-progress
                     --out ${CMAKE_BINARY_DIR}/check_runs/scenes_full/${scene})
    set_tests_properties(scenes_full_${scene} PROPERTIES LABELS "scenes;full" COST 20)
  endforeach()
  # The block in the bowl at smaller steps (docs/15_body_contact.md, the block in the bowl): once, every Δt
  # from 1/400 to 1/3200 s stopped on a line search that found no decrease; --compare's reference
  # runs at Δt/16.
  foreach(divisions 800 1600)
    add_test(NAME scenes_full_bowl_drop_dt_1_${divisions}
             COMMAND $<TARGET_FILE:fem_scene> ${FEM_ROOT}/scenes/bowl_drop.toml --set "time.step=\"1/${divisions}\""
                     --no-figures --no-progress --out ${CMAKE_BINARY_DIR}/check_runs/scenes_full/bowl_drop_dt_1_${divisions})
    set_tests_properties(scenes_full_bowl_drop_dt_1_${divisions} PROPERTIES LABELS "scenes;full" COST 40)
  endforeach()
endif()

if(FEM_BUILD_TESTS)
  # docs/scenes.md names only what exists and quotes the tables fem_scene --compare prints.
  add_test(NAME scenes_docs
           COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_docs.py --root ${FEM_ROOT}
                   --chapter scenes --bin ${CMAKE_BINARY_DIR}/bin --out ${CMAKE_BINARY_DIR}/check_docs/scenes)
  set_tests_properties(scenes_docs PROPERTIES LABELS "scenes;docs" COST 100)  # as chNN_docs
  # Bad command lines: refused before anything is computed or written.
  add_test(NAME scenes_bad_options
           COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_bad_options.py
                   --exe $<TARGET_FILE:fem_scene> --table ${FEM_ROOT}/tests/scenes/bad_options.txt)
  set_tests_properties(scenes_bad_options PROPERTIES LABELS "scenes;run")
  # The web page (--html) in headless Chromium, network off: the body drawn at its first and last
  # frame, and moved between them; every frame's positions read back through the page's own decoding
  # (its test hook) against the .vtu frames, within half a quantisation step. SKIP (exit 77) without
  # chromium or libjs-three (tools/setup.sh).
  add_test(NAME scenes_web_page_browser
           COMMAND ${Python3_EXECUTABLE} ${FEM_ROOT}/tools/check_web_page.py --exe $<TARGET_FILE:fem_scene>
                   --scene ${FEM_ROOT}/scenes/cantilever.toml --out ${CMAKE_BINARY_DIR}/check_runs/scenes_web_page)
  set_tests_properties(scenes_web_page_browser PROPERTIES LABELS "scenes;run" SKIP_RETURN_CODE 77 COST 10)
endif()
