# Warnings are errors for our own code only: generated protobuf/IDL code and
# system headers are compiled without them.
add_library(canfleet_warnings INTERFACE)
target_compile_options(canfleet_warnings INTERFACE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
                                                   -Wno-sign-conversion -Werror)

if(CANFLEET_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all)
  add_link_options(-fsanitize=address,undefined)
endif()

# canfleet_component(<target> [STATIC|INTERFACE] SOURCES ... DEPS ...)
# One call per module keeps each folder's CMakeLists a few lines long.
function(canfleet_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_DEPS} PRIVATE canfleet_warnings)
endfunction()

# canfleet_unit_test(<name> SOURCES ... DEPS ...): one GoogleTest binary per module,
# so a module's tests build without compiling the rest of the tree.
function(canfleet_unit_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main canfleet_warnings)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS unit)
  set_property(GLOBAL APPEND PROPERTY CANFLEET_UNIT_AND_INTEGRATION_TESTS ${name})
endfunction()

# canfleet_integration_test(<name> SOURCES ... DEPS ...): real sockets, real time, another program
# (tests/integration/CMakeLists.txt says what belongs there). Label "integration", generous timeout.
function(canfleet_integration_test name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest GTest::gmock GTest::gtest_main canfleet_warnings)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES LABELS integration TIMEOUT 300)
  set_property(GLOBAL APPEND PROPERTY CANFLEET_UNIT_AND_INTEGRATION_TESTS ${name})
endfunction()

if(CANFLEET_FUZZ)
  # Instrument all our libraries for coverage so libFuzzer can see inside them.
  add_compile_options(-fsanitize=fuzzer-no-link,address,undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
