"""What the tests share: paths, graph helpers (processes, collectors, domains), waits, bags,
machine capacity, network namespaces and foreign simulators."""
