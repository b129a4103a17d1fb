# Fuzz targets (docs/testing.md "Fuzzing"): tests/fuzz/fuzz_<name>.cpp defines
# LLVMFuzzerTestOneInput over one parser. The normal build links each with
# tests/fuzz/replay_main.cpp into fuzz_<name>_replay, and CTest fuzz/<name> runs it over the
# target's seed corpus and regression inputs (seconds; CI replays them without clang).
# -DOSR_FUZZ=ON (clang only, its own build folder: tools/fuzz.sh makes build-fuzz) builds every
# target with libFuzzer's coverage, AddressSanitizer and UndefinedBehaviorSanitizer, and each
# fuzz target as the libFuzzer executable fuzz_<name>.
option(OSR_FUZZ "libFuzzer executables with ASan and UBSan (clang; tools/fuzz.sh)" OFF)
if(OSR_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "OSR_FUZZ needs clang (CC=clang CXX=clang++), not ${CMAKE_CXX_COMPILER_ID}")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -g)
  add_link_options(-fsanitize=address,undefined)
endif()

set(OSR_FUZZ_TARGETS "")
# osr_fuzz_target(<name> SOURCES <files>... [LIBS <targets>...]): tests/fuzz/fuzz_<name>.cpp
# plus the parser's own sources or libraries.
function(osr_fuzz_target name)
  cmake_parse_arguments(ARG "" "" "SOURCES;LIBS" ${ARGN})
  set(dir ${CMAKE_CURRENT_SOURCE_DIR}/tests/fuzz)
  if(OSR_FUZZ)
    set(exe fuzz_${name})
    add_executable(${exe} ${dir}/fuzz_${name}.cpp ${ARG_SOURCES})
    target_link_options(${exe} PRIVATE -fsanitize=fuzzer)
  else()
    set(exe fuzz_${name}_replay)
    add_executable(${exe} ${dir}/fuzz_${name}.cpp ${ARG_SOURCES} ${dir}/replay_main.cpp)
    set(inputs ${dir}/corpus/${name})
    if(EXISTS ${dir}/regressions/${name})
      list(APPEND inputs ${dir}/regressions/${name})
    endif()
    # The seeds too big to copy, named in seeds_by_path.txt ("TARGET PATH" lines).
    file(STRINGS ${dir}/seeds_by_path.txt lines REGEX "^${name} ")
    foreach(line ${lines})
      string(REGEX REPLACE "^${name} +" "" path "${line}")
      list(APPEND inputs ${CMAKE_CURRENT_SOURCE_DIR}/${path})
    endforeach()
    add_test(NAME fuzz/${name} COMMAND ${exe} ${inputs})
    set_tests_properties(fuzz/${name} PROPERTIES TIMEOUT 120)
  endif()
  target_link_libraries(${exe} PRIVATE osr_common ${ARG_LIBS})
  target_include_directories(${exe} PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/tests)
  target_compile_options(${exe} PRIVATE ${OSR_WARNINGS})
  set(OSR_FUZZ_TARGETS ${OSR_FUZZ_TARGETS} ${exe} PARENT_SCOPE)
endfunction()
