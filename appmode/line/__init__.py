"""A serial line with no I/O: byte-time pacing, fault injection, and a board behind a
paced line each way (`Wire`). Uses `protocol` and `board`."""
