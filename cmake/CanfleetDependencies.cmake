# All dependencies come from Debian 12 packages through find_package (no vendored copies).
# scripts/install-deps.sh installs them.
find_package(Threads REQUIRED)
# Targets link spdlog::spdlog_header_only, not the compiled libspdlog: a node process then
# carries only the logging code it uses instead of loading all of libspdlog (0.3 MB less RSS per
# node, issue 7). All targets must use the same one (the header-only build defines the functions
# inline; mixing the two in one program would break the one-definition rule).
find_package(spdlog REQUIRED)
find_package(fmt REQUIRED)
find_package(CLI11 REQUIRED)
# zlib inflates the EDS every variant compiles in (node/devices/embedded_eds.hpp). Static: a node
# then carries inflate() alone rather than mapping all of libz.so (idle RSS, bench/idle/README.md).
set(ZLIB_USE_STATIC_LIBS ON)
find_package(ZLIB REQUIRED)

# Asio standalone has no CMake package in Debian: an INTERFACE target over its header.
find_path(ASIO_INCLUDE_DIR asio.hpp REQUIRED)
if(NOT TARGET asio::asio)
  add_library(asio::asio INTERFACE IMPORTED)
  # ASIO_DISABLE_STD_ALIGNED_ALLOC: Asio picks aligned_alloc or operator new depending on which
  # standard headers a file happened to include first; two choices in one program make ASan
  # report alloc-dealloc mismatches. One choice everywhere.
  set_target_properties(asio::asio PROPERTIES INTERFACE_INCLUDE_DIRECTORIES ${ASIO_INCLUDE_DIR}
                                              INTERFACE_COMPILE_DEFINITIONS "ASIO_STANDALONE;ASIO_DISABLE_STD_ALIGNED_ALLOC")
  target_link_libraries(asio::asio INTERFACE Threads::Threads)
endif()

if(CANFLEET_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
