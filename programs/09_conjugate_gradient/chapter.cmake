# Chapter 09's solver interface (linear_solver.hpp) offers "cholmod" when chapter 08's
# chapter.cmake found SuiteSparse's CHOLMOD (FEM_CHOLMOD_INCLUDE_DIR, FEM_CHOLMOD_LIBRARY).
# The library links it publicly, so every later chapter that picks a solver by name can use it.
# Included by fem_add_chapter, where ${lib} names the chapter's library.
if(FEM_CHOLMOD_INCLUDE_DIR AND FEM_CHOLMOD_LIBRARY)
  foreach(target IN LISTS chapter_libraries)
    target_include_directories(${target} SYSTEM PRIVATE ${FEM_CHOLMOD_INCLUDE_DIR})
    target_link_libraries(${target} PUBLIC ${FEM_CHOLMOD_LIBRARY})
    target_compile_definitions(${target} PRIVATE FEM_HAVE_CHOLMOD)
  endforeach()
  message(STATUS "Chapter 09: the solver interface offers \"cholmod\"")
else()
  message(STATUS "Chapter 09: CHOLMOD not found; the solver interface runs without \"cholmod\"")
endif()
