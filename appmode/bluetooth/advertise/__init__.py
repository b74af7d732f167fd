"""appmode as the car's Bluetooth module: a GATT application with the module's UART
service, an advertisement and an SPP server, registered with BlueZ, for a phone's app
(`application`); the module as a port that a board or `tap` serves (`port`); the names
it may advertise (`module_name`)."""
