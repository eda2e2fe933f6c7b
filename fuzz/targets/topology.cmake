canfleet_fuzz_target(topology DEPS canfleet_topology)
target_compile_definitions(fuzz_topology PRIVATE CANFLEET_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
