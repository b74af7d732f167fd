"""The host of the control port (UART2): `client.ControlHost`, its state machine
(`state`), the settings' reads and sets (`query`), `send --uart2`'s tokens (`tokens`)."""
