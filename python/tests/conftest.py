"""The Python package's tests run against real fleets (real processes, no mocks): the `fleet`
fixture and the `topology` marker come from the package's own pytest plugin (canfleet.pytest_plugin,
loaded through its pytest11 entry point)."""
