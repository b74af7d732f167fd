"""The terminal view of a driving session: the prompt_toolkit application, its key
bindings and the status panel. The session itself is in `session/`."""
