"""Who drives a shared car (`net.lease`, no I/O): a client whose lease was taken from it
drives no more (issue 80.8: a frozen driver woke up and drove again); a key holder
under the driver's id renews nothing and drives nothing (issue 80.4)."""

from __future__ import annotations

from appmode.net.lease import FIRST_PROOF, LAPSE, Granted, Lease, Refused, Revoked, Unproven
from appmode.net.proof import Proof, Prover


def test_a_lapsed_driver_is_revoked_and_another_link_drives() -> None:
    lease = Lease()
    assert lease.ask("laptop-1-aaa", "laptop", 0.0) == Granted()
    assert isinstance(lease.ask("phone-2-bbb", "phone", 0.1), Refused)
    assert lease.lapsed(LAPSE + 0.2) is not None  # its heartbeats stopped: the car stops
    assert lease.ask("laptop-1-aaa", "laptop", LAPSE + 0.3) == Revoked()  # it wakes up
    assert lease.ask("laptop-1-ccc", "laptop", LAPSE + 0.4) == Granted()  # its next link


def test_one_taken_over_or_stopped_is_revoked_one_that_let_go_is_not() -> None:
    lease = Lease()
    lease.ask("a-1-x", "a", 0.0)
    taken = lease.ask("b-1-y", "b", 0.1, take=True)
    assert isinstance(taken, Granted) and taken.took_from is not None
    assert lease.ask("a-1-x", "a", 0.2, take=True) == Revoked()
    assert lease.revoke("b-1-y") is not None  # a fleet stop
    assert lease.ask("b-1-y", "b", 0.3) == Revoked()
    lease.ask("c-1-z", "c", 0.4)
    assert lease.let_go("c-1-z") is not None  # it closed
    assert lease.ask("c-1-z", "c", 0.5) == Granted()


def _proof(words: str) -> Proof | None:
    return Proof.parse(words.split(" "))


def test_only_the_driver_s_proof_renews_its_lease_or_drives_under_its_id() -> None:
    lease = Lease()
    assert lease.ask("a-1-x", "a", 0.0) == Granted()
    assert lease.driver is not None
    driver, forger = Prover(), Prover()
    driver.secret, forger.secret = lease.driver.secret, "0" * 32
    beat = _proof(driver.words("alive", "a-1-x"))
    lease.beat("a-1-x", 0.2, beat)
    assert not lease.lapsed_at(0.2 + LAPSE)  # renewed at 0.2
    lease.beat("a-1-x", 0.4, beat)  # the same beat again, replayed
    lease.beat("a-1-x", 0.4, _proof(forger.words("alive", "a-1-x")))  # another secret
    lease.beat("a-1-x", 0.4, None)  # the bare id
    assert lease.lapsed_at(0.21 + LAPSE)
    write = _proof(driver.words("write", "a-1-x", "9.5", b"A"))
    assert not lease.proves("a-1-x", "write", write, "9.5", b"B")  # other bytes
    assert not lease.proves("a-1-x", "alive", write, "9.5", b"A")  # another kind
    assert not lease.proves("b-1-y", "write", write, "9.5", b"A")  # another id
    assert lease.proves("a-1-x", "write", write, "9.5", b"A")
    assert not lease.proves("a-1-x", "write", write, "9.5", b"A")  # once only
    assert lease.ask("a-1-x", "a", 0.3) == Unproven()
    assert lease.ask("a-1-x", "a", 0.3, proven=True) == Granted()


def test_a_driver_s_bare_beats_renew_its_lease_only_until_its_secret_can_have_come() -> None:
    """Over a slow link the secret takes a round trip to reach the driver: its bare
    heartbeats renew the lease until its first proven one, or FIRST_PROOF s."""
    lease = Lease()
    lease.ask("a-1-x", "a", 0.0)
    lease.beat("a-1-x", 0.25, None)
    assert not lease.lapsed_at(0.5)  # renewed at 0.25
    lease.beat("a-1-x", FIRST_PROOF + 0.1, None)
    assert lease.lapsed_at(0.25 + LAPSE + 0.01)  # that one renewed nothing
    fresh = Lease()
    fresh.ask("b-1-y", "b", 0.0)
    assert fresh.driver is not None
    prover = Prover()
    prover.secret = fresh.driver.secret
    fresh.beat("b-1-y", 0.1, _proof(prover.words("alive", "b-1-y")))
    fresh.beat("b-1-y", 0.3, None)  # proven once: bare ones renew nothing from now on
    assert fresh.lapsed_at(0.1 + LAPSE + 0.01)
