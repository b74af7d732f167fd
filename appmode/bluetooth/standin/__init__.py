"""A stand-in for BlueZ on a private D-Bus bus (`bus`): its adapter and devices
(`devices`, `bluez`), the GATT and advertising registrations of applications on its bus
(`registrations`, `peers`), classic SPP links through the profile API (`spp_links`), and
the endpoint that serves a simulated board as a module behind it (`endpoint`). bleak
drives it unmodified."""
