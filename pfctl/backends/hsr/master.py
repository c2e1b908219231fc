"""The ROS master's XML-RPC API with a socket timeout (rospy's own calls have none: a master that
is down or unreachable would hang a node in ``init_node``, or a watchdog in its ping)."""

from __future__ import annotations

import http.client
import xmlrpc.client

MASTER_TIMEOUT = 1.0
"""Default socket timeout of one call to the master, seconds."""


class _TimeoutTransport(xmlrpc.client.Transport):
    """XML-RPC over HTTP with a socket timeout."""

    def __init__(self, timeout: float) -> None:
        super().__init__()
        self._timeout = timeout

    def make_connection(self, host):  # type: ignore[no-untyped-def]
        conn = super().make_connection(host)
        conn.timeout = self._timeout
        return conn


def master_proxy(uri: str, timeout: float = MASTER_TIMEOUT) -> xmlrpc.client.ServerProxy:
    """A proxy to the master at ``uri`` whose calls give up after ``timeout`` seconds (they
    raise ``OSError``, e.g. ``TimeoutError`` or ``ConnectionRefusedError``)."""
    return xmlrpc.client.ServerProxy(uri, transport=_TimeoutTransport(timeout))


MASTER_ERRORS = (OSError, xmlrpc.client.Error)
"""What a call through :func:`master_proxy` raises when the master does not answer properly."""


class MasterError(Exception):
    """The ROS master did not answer ``getPid``: ``error`` is what the call raised (no master
    there), or None when the master answered with a failure, ``answer`` its message."""

    def __init__(self, error: BaseException | None, answer: str = "") -> None:
        super().__init__(str(error) if error is not None else answer)
        self.error = error
        self.answer = answer


def check_master(uri: str, caller: str, timeout: float = MASTER_TIMEOUT) -> None:
    """Raise :class:`MasterError` unless the ROS master at ``uri`` answers ``getPid`` (as
    ``caller``) within ``timeout`` seconds: ``rospy.init_node`` would wait for it forever."""
    try:
        code, message, _ = master_proxy(uri, timeout).getPid(caller)
    except (*MASTER_ERRORS, http.client.HTTPException, ValueError) as err:
        raise MasterError(err) from None
    if code != 1:
        raise MasterError(None, str(message))


__all__ = ["MASTER_ERRORS", "MASTER_TIMEOUT", "MasterError", "check_master", "master_proxy"]
