"""A car on the network, over Eclipse Zenoh (the extra `net`): `share.Share`
puts a car a machine reaches on Zenoh under `appmode/NAME/…` and is its stop authority
(a driver holds a lease, renewed by its heartbeats: `lease`); `remote_port.RemoteSerial`
is that car as a pyserial port on another machine (`zenoh://NAME?connect=…&key=…`, so
every command and session drives it as a local one); `fleet` lists the cars a key
opens and stops them. What the key expressions are is `names`; one name, one car,
`hosts`; what a query to a car's host says, read as data from outside, `asked`; how a
Zenoh session is configured (the key is Zenoh's user-password authentication) is
`config`."""
