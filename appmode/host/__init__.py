"""The host side: its state machine, parameter queries, send tokens, and `Host`, the
host over a link. Uses `protocol` and `ports`."""
