"""The ``lumpbeam`` command line: one module per subcommand, each parsing and delegating."""
