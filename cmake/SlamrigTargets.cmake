# Shared compile settings and helpers for every slamrig target.

# One place for warnings, floating-point determinism and sanitizers.
function(slamrig_set_target_options target)
  target_compile_options(${target} PRIVATE
    -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Wno-sign-conversion
    # GCC 12 reports impossible overlaps inside std::string operator+ (GCC bug 105651).
    $<$<CXX_COMPILER_ID:GNU>:-Wno-restrict>
    # GCC 12 at -O2 flags std::variant copies of records as maybe-uninitialized (false positives,
    # GCC bugs 80635 and 105593); -Wuninitialized stays on.
    $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>
    # Same results whatever the compiler decides about fused multiply-add.
    -ffp-contract=off)
  if(SLAMRIG_SANITIZE)
    target_compile_options(${target} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer
                                             -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(SLAMRIG_FUZZ)
    # Coverage instrumentation for libFuzzer on every target; the fuzz executables add
    # -fsanitize=fuzzer at link time (fuzz/CMakeLists.txt).
    target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link,address,undefined
                                             -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    target_link_options(${target} PRIVATE -fsanitize=address,undefined)
  endif()
  if(SLAMRIG_VALIDATE)
    target_compile_definitions(${target} PRIVATE SLAMRIG_VALIDATE=1)
  endif()
endfunction()

# Unity build: a target's sources compiled a few at a time as one translation unit, so that the
# headers they share (Eigen's above all) are parsed and instantiated once per batch instead of
# once per file; the main job builds in about half the compiler time. Files of one target must
# then not define the same names in their anonymous namespaces. Off, every file is compiled
# alone: scripts/test.sh's sanitizer build does that for every library the unit tests link, so a
# missing include there still fails CI (not in apps/*.cc or the Python bridge, which it does not
# build).
function(slamrig_unity_build target)
  if(SLAMRIG_UNITY_BUILD)
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
    # A batch includes its files, so GCC takes a type private to one of them, held by a class
    # that is not (a pimpl), for a header's mistake; without batches it still warns where it
    # should.
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-Wno-subobject-linkage>)
  endif()
endfunction()

# slamrig_add_library(name SOURCES ... [PUBLIC_DEPS ...] [PRIVATE_DEPS ...])
function(slamrig_add_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  slamrig_set_target_options(${name})
  slamrig_unity_build(${name})
  if(SLAMRIG_PYTHON)
    # The Python module links these static libraries into a shared object. No semantic
    # interposition and no PLT keep most of the speed of position-dependent code: the map
    # correlator's benchmark is 22 % slower with -fPIC alone, unchanged with both (README, Python).
    set_target_properties(${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    target_compile_options(${name} PRIVATE $<$<CXX_COMPILER_ID:GNU>:-fno-semantic-interposition>
                                           -fno-plt)
  endif()
endfunction()

# slamrig_add_test(name SOURCES ... DEPS ... [LABEL unit|integration|scenario] [SLOW_CASES ...])
# One gtest executable, run by ctest as one test (all its cases in one process: a process that
# links OpenCV costs ~0.1 s to start, so one ctest entry per case would dominate the unit suite).
# SLOW_CASES (gtest names, Suite.Case) of a unit test run as a second ctest entry, <name>.slow,
# labelled integration, so that the unit label stays fast without splitting the sources.
# Run a single case with `build/<dir>/<name> --gtest_filter=Suite.Case`.
function(slamrig_add_test name)
  if(NOT SLAMRIG_BUILD_TESTS)
    return()
  endif()
  cmake_parse_arguments(ARG "" "LABEL" "SOURCES;DEPS;SLOW_CASES" ${ARGN})
  if(NOT ARG_LABEL)
    set(ARG_LABEL unit)
  endif()
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gtest_main GTest::gmock)
  target_compile_definitions(${name} PRIVATE SLAMRIG_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  target_include_directories(${name} PRIVATE ${PROJECT_SOURCE_DIR})
  slamrig_set_target_options(${name})
  if(ARG_SLOW_CASES)
    list(JOIN ARG_SLOW_CASES ":" slow)
    add_test(NAME ${name} COMMAND ${name} --gtest_filter=-${slow}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    add_test(NAME ${name}.slow COMMAND ${name} --gtest_filter=${slow}
             WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    set_tests_properties(${name}.slow PROPERTIES LABELS integration)
  else()
    add_test(NAME ${name} COMMAND ${name} WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
  endif()
  set_tests_properties(${name} PROPERTIES LABELS ${ARG_LABEL})
  # `cmake --build B --target slamrig_unit_tests` builds what `ctest -L unit` runs, and nothing
  # else (the sanitizer stage of scripts/test.sh).
  if(ARG_LABEL STREQUAL "unit")
    if(NOT TARGET slamrig_unit_tests)
      add_custom_target(slamrig_unit_tests)
    endif()
    add_dependencies(slamrig_unit_tests ${name})
  endif()
endfunction()
