"""Working with transcripts: the conformance matcher and runner, replay, tap, dump and
plot, and the shipped conformance suite (`suite/`). The format itself is low, in
`appmode.protocol.transcript`, so that the board server can record too."""
