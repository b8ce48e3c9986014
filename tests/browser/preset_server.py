"""A page served for one named preset (its own server), for browser tests that need a particular drive."""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from typing import Any

from tests.browser.conftest import UiServer, open_page
from tests.net import free_port


@contextlib.contextmanager
def preset_server(name: str) -> Iterator[UiServer]:
    """Serve the page on preset ``name`` (no 3D scene) until the block ends."""
    from pmsm_commissioning.app.io.presets import load_preset
    from pmsm_commissioning.app.ui.page import create_server

    srv, config = create_server(load_preset(name), name, port=free_port(), scene_3d=False)
    try:
        yield UiServer(f"http://127.0.0.1:{srv.get_port()}", srv, config)
    finally:
        srv.stop()


@contextlib.contextmanager
def preset_page(browser: Any, server: UiServer) -> Iterator[Any]:
    """One connected page of ``server`` in its own browser context."""
    context, pg = open_page(browser, server)
    try:
        yield pg
    finally:
        context.close()
