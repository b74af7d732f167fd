"""The host side: what drives a board. `link.Link` opens a board by its Target, writes,
reads and reopens a lost link; `app/` is the host of the APP port (`app.client.Host`,
its state machine, parameter queries, send tokens), `control/` the host of the control
port (`control.client.ControlHost`, the same parts); what both share is here (the
events, a query's failure, the link's counters, waits). `probe` and `identify` tell
what a port is. Uses `protocol`, `board` and `ports`."""
