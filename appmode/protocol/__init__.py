"""The wire grammars, with no I/O: the APP codec, the parameter and direction tables,
escaping, one-line and JSON views of events, and the transcript format.

Nothing here imports from another appmode layer (only `appmode.errors`).
"""
