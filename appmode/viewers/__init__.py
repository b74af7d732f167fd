"""What people watch a car in beside appmode's own views: Foxglove (and Lichtblick),
live over the official foxglove-sdk (`live`). The channels are `protocol.channels`'s, as
an MCAP recording has them (`protocol.mcap_format`)."""
