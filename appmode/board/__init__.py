"""The firmware model: the board as a state machine with an injected clock, its body
(kinematics, battery) and its non-volatile stores. Uses `protocol` only."""
