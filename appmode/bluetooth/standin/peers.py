"""The stand-in's server side: BlueZ's GattManager1, LEAdvertisingManager1 and a
server-role Profile1, with what a second machine's BlueZ would show a central. An
application registered on the bus (appmode's advertised module, or any program written
for BlueZ) appears to a central on the same bus as a nearby device: its advertisement is
heard while discovering, a connection resolves its GATT services (each call to a
characteristic is forwarded to the application, each notification back), and an SPP
server profile appears as a paired classic device whose links reach the server's
NewConnection with a real socket.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable, Coroutine
from functools import partial
from itertools import count
from typing import Any

from dbus_fast import DBusError, Message, Variant
from dbus_fast.aio import MessageBus
from dbus_fast.service import ServiceInterface

from appmode.bluetooth.calls import add_match, call
from appmode.bluetooth.gatt import Cccd, GattService, UartCharacteristic
from appmode.bluetooth.module import MTU
from appmode.bluetooth.standin.devices import ADAPTER, Device, Radio, device_path
from appmode.bluetooth.standin.registrations import (
    ADVERTISING,
    GATT,
    AdvertisingManager,
    GattManager,
    Peer,
)
from appmode.bluetooth.standin.spp_links import SppLinks
from appmode.bluetooth.uuids import SPP

Log = Callable[[str], None]
CENTRAL_ADDRESS = "02:CA:40:00:00:01"
CENTRAL = device_path(CENTRAL_ADDRESS)
"""The central as the application's BlueZ shows it (a Device1, connected while it has
a link): the stand-in's own adapter."""
CHARACTERISTIC = "org.bluez.GattCharacteristic1"
INVALID = "org.bluez.Error.InvalidArguments"
_addresses = count(1)


class Peers:
    """The applications on the bus, and the devices a central sees for them."""

    def __init__(self, radio: Radio, log: Log, discovering: Callable[[], bool]) -> None:
        self._radio, self._log, self._discovering = radio, log, discovering
        self._bus: MessageBus | None = None
        self._peers: dict[str, Peer] = {}
        self.spp_links = SppLinks(log, self._central_changed)
        self._central = Device(_CentralRadio(self), CENTRAL_ADDRESS, "appmode-standin", [], le=True)
        self._centrals: dict[str, set[Device]] = {}
        self._watched: set[str] = set()
        self._exported: set[str] = set()
        """The peer devices each central connected, by its bus name."""
        self._tasks: set[asyncio.Task[None]] = set()
        self.advertising = AdvertisingManager(lambda: sum(1 for p in self.all() if p.advertisement))

    def start(self, bus: MessageBus) -> None:
        self._bus = bus
        bus.export(ADAPTER, GattManager())
        bus.export(ADAPTER, self.advertising)

    def all(self) -> list[Peer]:
        return list(self._peers.values())

    def owner(self, device: Device) -> Peer | None:
        """The peer a device stands for, if it is one's."""
        return next((p for p in self._peers.values() if device in (p.ble, p.spp)), None)

    # ------------------------------------------------------------ registrations

    def handle(self, message: Message) -> bool:
        """GattManager1's and LEAdvertisingManager1's calls; True when one was taken. A
        central's Connect to a peer's device is noted and left to the device."""
        if message.interface == "org.bluez.Device1" and (message.member or "").startswith(
            "Connect"
        ):
            self._note_central(message)
            return False
        if message.path != ADAPTER or message.interface not in (GATT, ADVERTISING):
            return False
        if message.signature not in ("oa{sv}", "o") or not message.body:
            self._reply(message, INVALID, "bad call")
            return True
        self.spawn(self._register(message))
        return True

    def _reply(self, message: Message, error: str = "", why: str = "") -> None:
        assert self._bus is not None
        if error:
            self._bus.send(Message.new_error(message, error, why))
        else:
            self._bus.send(Message.new_method_return(message))

    async def _register(self, message: Message) -> None:
        sender, path = str(message.sender), str(message.body[0])
        peer = self._peers.get(sender)
        try:
            if message.member == "RegisterApplication":
                peer = await self._watch(sender)
                await self._application(peer, path)
            elif message.member == "RegisterAdvertisement":
                peer = await self._watch(sender)
                await self._advertisement(peer, path)
            elif message.member == "UnregisterApplication" and peer and peer.application == path:
                peer.application = ""
                self._hide(peer)
            elif (
                message.member == "UnregisterAdvertisement" and peer and peer.advertisement == path
            ):
                peer.advertisement = ""
                self._hide(peer)
            else:
                raise DBusError("org.bluez.Error.DoesNotExist", f"{path} is not registered")
        except DBusError as exc:
            self._reply(message, exc.type, exc.text)
            return
        self._reply(message)
        self._show(peer)

    def _note_central(self, message: Message) -> None:
        """Who connects a peer's device: if it leaves the bus, its links end, as a
        phone's system ends the links of an app that died."""
        device = next(
            (
                d
                for p in self._peers.values()
                for d in (p.ble, p.spp)
                if d and d.path == message.path
            ),
            None,
        )
        sender = str(message.sender)
        if device is None:
            return
        if sender not in self._centrals:
            self._centrals[sender] = set()
            self.spawn(self.watch_name(sender))
        self._centrals[sender].add(device)

    def spawn(self, work: Coroutine[object, object, None]) -> None:
        task = asyncio.ensure_future(work)
        self._tasks.add(task)
        task.add_done_callback(self._tasks.discard)

    async def _watch(self, sender: str) -> Peer:
        """The sender's peer; a new one is dropped when its sender leaves the bus."""
        if sender not in self._peers:
            self._peers[sender] = Peer(sender)
            await self.watch_name(sender)
            await self._add_match(
                f"type='signal',sender='{sender}',interface='org.freedesktop.DBus.Properties',"
                "member='PropertiesChanged'"
            )
        return self._peers[sender]

    async def watch_name(self, sender: str) -> None:
        """Hear when `sender` leaves the bus (a NameOwnerChanged signal)."""
        if sender not in self._watched:
            self._watched.add(sender)
            await self._add_match(
                "type='signal',sender='org.freedesktop.DBus',member='NameOwnerChanged',"
                f"arg0='{sender}'"
            )

    async def _add_match(self, rule: str) -> None:
        assert self._bus is not None
        await add_match(self._bus, rule)

    async def _ask(
        self,
        destination: str,
        path: str,
        interface: str,
        member: str,
        signature: str,
        body: list[Any],
    ) -> Any:
        """A call's first return value; DBusError when it fails."""
        assert self._bus is not None
        reply = await call(self._bus, destination, path, interface, member, signature, body)
        return reply.body[0] if reply.body else None

    async def _application(self, peer: Peer, path: str) -> None:
        """Read the application's objects, as BlueZ does (its ObjectManager)."""
        objects: dict[str, dict[str, dict[str, Variant]]] = await self._ask(
            peer.sender, path, "org.freedesktop.DBus.ObjectManager", "GetManagedObjects", "", []
        )
        services, characteristics, secured = {}, {}, set()
        for where, interfaces in sorted(objects.items()):
            if "org.bluez.GattService1" in interfaces:
                services[where] = str(interfaces["org.bluez.GattService1"]["UUID"].value)
            if CHARACTERISTIC in interfaces:
                props = interfaces[CHARACTERISTIC]
                characteristics[where] = (str(props["UUID"].value), str(props["Service"].value))
                flags = props.get("Flags", Variant("as", [])).value
                if any(flag.startswith(("encrypt-", "secure-")) for flag in flags):
                    secured.add(where)
        if not services or any(s not in services for _, s in characteristics.values()):
            raise DBusError(INVALID, f"{path}: no GATT service, or a characteristic outside one")
        peer.application, peer.services, peer.characteristics = path, services, characteristics
        peer.secured = secured

    async def _advertisement(self, peer: Peer, path: str) -> None:
        props: dict[str, Variant] = await self._ask(
            peer.sender,
            path,
            "org.freedesktop.DBus.Properties",
            "GetAll",
            "s",
            ["org.bluez.LEAdvertisement1"],
        )
        if props.get("Type", Variant("s", "")).value != "peripheral":
            raise DBusError(INVALID, "only a connectable (peripheral) advertisement is heard here")
        peer.advertisement = path
        peer.name = str(props.get("LocalName", Variant("s", "")).value)
        peer.service_uuids = [
            str(u).lower() for u in props.get("ServiceUUIDs", Variant("as", [])).value
        ]

    def profile(self, sender: str, path: str, options: dict[str, Variant], added: bool) -> None:
        """A server-role SPP profile registered (or not any more): a paired classic
        device stands for it."""
        peer = self._peers.get(sender)
        if added:
            peer = self._peers.setdefault(sender, Peer(sender))
            peer.spp_server = path
            name = options.get("Name", Variant("s", "SPP")).value
            peer.spp = Device(self._radio, _address(), str(name), [SPP], le=False)
            self._export(peer, peer.spp.path, peer.spp)
            self._log(f"spp: {peer.spp.label} offered by {sender}")
        elif peer is not None and peer.spp_server == path:
            self._unexport_device(peer, peer.spp)
            peer.spp_server, peer.spp = "", None

    def _show(self, peer: Peer | None) -> None:
        """A peer with an application and an advertisement is heard as a device."""
        if peer is None or peer.ble is not None or not (peer.application and peer.advertisement):
            return
        peer.ble = Device(self._radio, _address(), peer.name, peer.service_uuids, le=True)
        self._log(f"ble: {peer.name or peer.ble.address} advertised by {peer.sender}")
        if self._discovering():
            self.discovered()

    def discovered(self) -> None:
        """Discovery is on: every advertised device not yet known is found."""
        for peer in self._peers.values():
            if peer.ble is not None and peer.ble.path not in peer.exported:
                self._export(peer, peer.ble.path, peer.ble)

    def heard(self) -> list[Device]:
        """The advertised devices a central has found."""
        return [
            p.ble for p in self._peers.values() if p.ble is not None and p.ble.path in p.exported
        ]

    def _hide(self, peer: Peer) -> None:
        if peer.ble is not None:
            self._unexport_device(peer, peer.ble)
            peer.ble, peer.proxies = None, {}

    def gone(self, message: Message) -> bool:
        """A peer's sender left the bus: its devices go (a central's links end). A
        central left: the links it made end."""
        if message.member != "NameOwnerChanged" or message.signature != "sss":
            return False
        name, _, new = message.body
        if new:
            return False
        self._watched.discard(name)
        for linked in self._centrals.pop(name, set()):
            if linked.connected:
                self._log(f"{name}, which connected {linked.label}, left the bus")
                self._radio.disconnect(linked)
        peer = self._peers.get(name)
        if peer is None:
            return False
        self._unexport_device(peer, peer.ble)
        self._unexport_device(peer, peer.spp)
        del self._peers[name]
        self._log(f"{name} left the bus: what it registered is gone")
        return True

    def _export(self, peer: Peer, path: str, interface: ServiceInterface) -> None:
        assert self._bus is not None
        self._bus.export(path, interface)
        peer.exported.append(path)

    def _unexport_device(self, peer: Peer, device: Device | None) -> None:
        if device is None:
            return
        self._radio.disconnect(device)
        assert self._bus is not None
        mine = [p for p in peer.exported if p == device.path or p.startswith(device.path + "/")]
        for path in mine[::-1]:
            self._bus.unexport(path)
            peer.exported.remove(path)

    # ------------------------------------------------------------ a central's links

    def connect_ble(self, peer: Peer, device: Device) -> None:
        """A central connects: the application's services appear under the device."""
        if not peer.proxies:
            self._resolve(peer, device)
        device.set_state(True)
        self._log(f"ble: {device.label} connected")
        self._central_changed()

    def _resolve(self, peer: Peer, device: Device) -> None:
        handles = count(0x10)
        services: dict[str, str] = {}
        for number, (where, uuid) in enumerate(peer.services.items()):
            services[where] = f"{device.path}/service{next(handles):04x}"
            self._export(peer, services[where], GattService(uuid, device.path, number))
        for where, (uuid, service) in peer.characteristics.items():
            handle = next(handles)
            path = f"{services[service]}/char{handle:04x}"
            proxy = UartCharacteristic(
                uuid,
                services[service],
                handle,
                partial(self._write, peer, where),
                partial(self._subscribe, peer, where),
            )
            peer.proxies[where] = proxy
            self._export(peer, path, proxy)
            ccc = next(handles)
            self._export(peer, f"{path}/desc{ccc:04x}", Cccd(path, ccc))

    def disconnect_ble(self, peer: Peer, device: Device) -> None:
        """The link ends: BlueZ stops the notifications the central asked for."""
        for proxy in peer.proxies.values():
            if proxy.notifying:
                proxy.set_notifying(False)
        if device.connected:
            device.set_state(False)
            self._log(f"ble: {device.label} disconnected")
        self._central_changed()

    def _central_changed(self) -> None:
        """The central's device, as the applications' BlueZ shows it: connected while
        any of its links to them is up."""
        linked = [d for p in self._peers.values() for d in (p.ble, p.spp) if d and d.connected]
        if linked and self._bus is not None and self._central.path not in self._exported:
            self._bus.export(self._central.path, self._central)
            self._exported.add(self._central.path)
        self._central.set_state(bool(linked))

    def drop_central(self) -> None:
        """An application disconnected the central: every link it has ends."""
        for peer in self.all():
            for device in (peer.ble, peer.spp):
                if device is not None and device.connected:
                    self._radio.disconnect(device)

    def _write(self, peer: Peer, path: str, data: bytes, _: str) -> None:
        """A central's write, forwarded in order (write without response: no wait); the
        application hears it from the central's device. One to a characteristic that
        asks for an authenticated link is dropped until the central has paired."""
        if path in peer.secured and not (peer.ble is not None and peer.ble.paired):
            self._log(f"ble: a write to {path} refused: insufficient authentication (pair first)")
            return
        options = {
            "device": Variant("o", CENTRAL),
            "link": Variant("s", "LE"),
            "mtu": Variant("q", MTU),
            "type": Variant("s", "command"),
        }
        self._send(peer, path, "WriteValue", "aya{sv}", [data, options])

    def _subscribe(self, peer: Peer, path: str, on: bool) -> None:
        self._send(peer, path, "StartNotify" if on else "StopNotify", "", [])

    def _send(self, peer: Peer, path: str, member: str, signature: str, body: list[Any]) -> None:
        if self._bus is not None and self._bus.connected:
            self._bus.send(
                Message(
                    destination=peer.sender,
                    path=path,
                    interface=CHARACTERISTIC,
                    member=member,
                    signature=signature,
                    body=body,
                )
            )

    def notified(self, message: Message) -> bool:
        """An application's notification (a PropertiesChanged of Value) reaches the
        central through the device's characteristic."""
        peer = self._peers.get(str(message.sender))
        if peer is None or message.member != "PropertiesChanged" or message.signature != "sa{sv}as":
            return False
        proxy = peer.proxies.get(str(message.path))
        interface, changed, _ = message.body
        if proxy is None or interface != CHARACTERISTIC or "Value" not in changed:
            return False
        if peer.ble is not None and peer.ble.connected:
            proxy.notify(bytes(changed["Value"].value))
        return True

    async def connect_spp(self, peer: Peer, device: Device, client: tuple[str, str]) -> None:
        """A central's SPP link to the server (`client`: the central's profile)."""
        assert self._bus is not None
        server = (peer.sender, peer.spp_server)
        await self.spp_links.connect(self._bus, device, client, server, CENTRAL)

    def close(self) -> None:
        for task in list(self._tasks):
            task.cancel()
        self.spp_links.close()


class _CentralRadio:
    """What the central's device does when an application calls it."""

    def __init__(self, peers: Peers) -> None:
        self._peers = peers

    async def connect(self, device: Device, uuid: str | None) -> None:
        raise DBusError("org.bluez.Error.NotSupported", "the central connects, not the module")

    def disconnect(self, device: Device) -> None:
        self._peers.drop_central()


def _address() -> str:
    """A new locally administered address for a peer's device."""
    number = next(_addresses)
    return f"02:CA:40:01:{number // 256 % 256:02X}:{number % 256:02X}"
