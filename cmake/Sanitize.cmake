# Checking builds, each in a build folder of its own (scripts/test.sh makes one
# with both): GI_SANITIZE compiles everything with AddressSanitizer and
# UndefinedBehaviorSanitizer, and the unit tests and the hostile-input test
# then carry the label 'sanitize'; GI_FUZZ adds the libFuzzer target of the
# mesh readers (tests/fuzz, label 'fuzz'; clang only).
option(GI_SANITIZE "Build with AddressSanitizer + UndefinedBehaviorSanitizer (tests labelled 'sanitize')" OFF)
option(GI_FUZZ "Build the libFuzzer target of the mesh readers (needs clang; tests labelled 'fuzz')" OFF)

if(GI_SANITIZE)
  # Any finding stops the program (no recovery), with a stack of file:line.
  set(GI_SANITIZE_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  if(CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    list(APPEND GI_SANITIZE_FLAGS -gline-tables-only)
  else()
    list(APPEND GI_SANITIZE_FLAGS -g1)
  endif()
  add_compile_options(${GI_SANITIZE_FLAGS})
  add_link_options(-fsanitize=address,undefined)
endif()

if(GI_FUZZ AND NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "GI_FUZZ needs clang (libFuzzer): configure with -DCMAKE_CXX_COMPILER=clang++")
endif()

# Compile time of the checking build on two CI cores: the engine and the
# readers at -O1 (the tests run their hot loops; -O1 is what the sanitizers'
# documentation advises), the command-line tool and the test sources at -O0
# (heavy templates: CLI11, JSON, GoogleTest; little run time of their own).
# Called at the end of the top-level CMakeLists, once every target exists.
function(gi_sanitize_optimization)
  if(NOT GI_SANITIZE)
    return()
  endif()
  foreach(t gi_core gi_io gi_io_ply gi_fuzz_mesh)
    if(TARGET ${t})
      target_compile_options(${t} PRIVATE -O1)
    endif()
  endforeach()
  foreach(t gi gi-scenes gi_unit_tests)
    if(TARGET ${t})
      target_compile_options(${t} PRIVATE -O0)
    endif()
  endforeach()
endfunction()
