"""How long hold-to-drive keeps a direction after a key press (`hold`): the first
timeout outlasts the OS's delay before a held key repeats, the second its repeat rate.
Apart from `hold` so that `drive --help` names them without loading the session."""

FIRST_TIMEOUT = 0.6
REPEAT_TIMEOUT = 0.15
