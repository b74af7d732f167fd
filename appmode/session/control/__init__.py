"""A session on the control port: velocity frames, turns, the ten settings and the
encoder report, with the APP port of the same board beside it
(`session.ControlSession`), its commands (`commands`) and what it shows (`status`)."""
