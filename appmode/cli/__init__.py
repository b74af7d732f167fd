"""The `appmode` command line: one module per command (its arguments and its `run`),
collected by `appmode.cli.main`."""
