"""A session on a WHEELTEC chassis port: velocities in SI from keys, sticks and twists,
held by re-sending them (`session.ChassisSession`), its commands (`commands`) and what it
shows (`status`)."""
