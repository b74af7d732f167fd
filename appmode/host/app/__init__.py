"""The host of the APP port (UART3): `client.Host`, its state machine (`state`), the
parameter queries (`query`), `send`'s tokens (`tokens`) and the check that a stop took
(`stop_check`)."""
