"""Bluetooth: the car's module reached directly, appmode as the car's module, and a
stand-in for BlueZ. What the three share is here: the UART services (`uuids`), a
module's buffer and pacing (`module`), GATT objects (`gatt`), D-Bus calls (`calls`,
`signatures`), the asyncio loop of a pyserial port (`loop`, `inbox`), and what each
platform lacks (`availability`).

- `links/`: the host's links — `ble://` (bleak) and `bt://` (BlueZ's profile API) as
  pyserial ports (`links.ble_port.BleSerial`, `links.spp_port.SppSerial`) and the
  nearby modules (`links.scan.scan`);
- `advertise/`: appmode as the car's module, for the vendor's phone app — a GATT
  application, an advertisement and an SPP server registered with BlueZ
  (`advertise.application.AdvertisedModule`, `appmode board --advertise`, `tap
  advertise:`), as a port (`advertise.port`);
- `standin/`: the BlueZ stand-in on a private D-Bus bus (`standin.bluez.StandIn`), which
  serves a simulated board as a module (`standin.endpoint.BluetoothEndpoint`, `appmode
  board --bluetooth`) and applications registered on its bus as nearby devices.
"""
