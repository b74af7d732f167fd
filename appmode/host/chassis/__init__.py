"""The host of a WHEELTEC chassis port: `client.ChassisHost`, its state machine (`state`)
and `send --chassis`'s tokens (`tokens`)."""
