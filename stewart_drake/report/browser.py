"""Headless Chromium driven through the DevTools protocol: open a page, collect console errors,
evaluate JavaScript, take screenshots. Used by the browser tests and ``scripts/screenshots``.

Chromium is Debian's ``chromium`` package (``scripts/ensure-chromium`` installs it); the DevTools
client is ``websocket-client``. ``find_chromium`` returns None when either is missing, so callers can
skip with a message instead of failing.
"""

from __future__ import annotations

import base64
import io
import json
import os
import shutil
import signal
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

CHROMIUM_NAMES = ("chromium", "chromium-browser", "google-chrome", "chrome")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-default-apps",
    "--mute-audio",
    "--hide-scrollbars",
    # WebGL on the CPU (SwiftShader) for Meshcat's canvas: Chromium no longer falls back to it silently.
    "--enable-unsafe-swiftshader",
    "--use-angle=swiftshader",
)


def find_chromium() -> str | None:
    """The Chromium executable, or None when it (or the ``websocket`` client) is not installed."""
    try:
        import websocket  # noqa: F401
    except ImportError:
        return None
    return next((p for p in map(shutil.which, CHROMIUM_NAMES) if p), None)


class Browser:
    """One headless Chromium with one page tab. ``with Browser() as b: b.open(url); b.evaluate(js)``.

    ``errors`` collects console errors and uncaught exceptions of the page (strings)."""

    def __init__(self, width: int = 1280, height: int = 900, executable: str | None = None, timeout: float = 30.0):
        self.executable = executable or find_chromium()
        if self.executable is None:
            raise RuntimeError(
                "Chromium (or the websocket-client package) is not installed; run scripts/ensure-chromium"
            )
        self.width, self.height, self.timeout = width, height, timeout
        self.errors: list[str] = []
        self._id = 0
        self._events: list[dict] = []

    def __enter__(self) -> Browser:
        import websocket

        self._dir = tempfile.TemporaryDirectory(prefix="stewart-chromium-")
        self._proc = subprocess.Popen(
            [
                self.executable,
                *FLAGS,
                f"--user-data-dir={self._dir.name}",
                "--remote-debugging-port=0",
                "--remote-allow-origins=*",
                f"--window-size={self.width},{self.height}",
                "about:blank",
            ],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,  # its own process group: its helpers (zygote, crashpad) end with it
        )
        port_file = Path(self._dir.name) / "DevToolsActivePort"
        deadline = time.monotonic() + self.timeout
        while not (port_file.exists() and port_file.read_text().strip()):
            if time.monotonic() > deadline or self._proc.poll() is not None:
                self.__exit__(None, None, None)
                raise RuntimeError("Chromium did not start its DevTools endpoint")
            time.sleep(0.05)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=self.timeout) as r:
            page = next(t for t in json.load(r) if t["type"] == "page")
        self._ws = websocket.create_connection(page["webSocketDebuggerUrl"], timeout=self.timeout, suppress_origin=True)
        for domain in ("Page", "Runtime", "Log"):
            self.send(f"{domain}.enable")
        self.send(
            "Emulation.setDeviceMetricsOverride",
            width=self.width,
            height=self.height,
            deviceScaleFactor=1,
            mobile=False,
        )
        return self

    def __exit__(self, *exc) -> None:
        if getattr(self, "_ws", None) is not None:
            self._ws.close()
        self._signal_group(signal.SIGTERM)
        try:
            self._proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            pass
        # Chromium's helper processes may still be writing the profile after the browser exits (a teardown once
        # failed with "Directory not empty: 'Default'" under load): end the whole group before removing it
        self._signal_group(signal.SIGKILL)
        self._proc.wait()
        self._dir.cleanup()

    def _signal_group(self, sig) -> None:
        """Send ``sig`` to Chromium's process group (gone already: nothing to do)."""
        try:
            os.killpg(self._proc.pid, sig)
        except ProcessLookupError:
            pass

    # -- protocol ------------------------------------------------------------------------------

    def _record(self, msg: dict) -> None:
        method, p = msg.get("method"), msg.get("params", {})
        if method == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
            self.errors.append(" ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
        elif method == "Runtime.exceptionThrown":
            d = p.get("exceptionDetails", {})
            self.errors.append(d.get("exception", {}).get("description") or d.get("text", "exception"))
        elif method == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
            self.errors.append(f"{p['entry'].get('text', '')} {p['entry'].get('url', '')}".strip())
        self._events.append(msg)

    def send(self, method: str, **params) -> dict:
        """Send one DevTools command and return its result (raises on a protocol error)."""
        self._id += 1
        self._ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            msg = json.loads(self._ws.recv())
            if msg.get("id") == self._id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg.get("result", {})
            self._record(msg)

    def _pump(self, seconds: float) -> None:
        """Read events for ``seconds`` (console messages arrive asynchronously)."""
        import websocket

        end = time.monotonic() + seconds
        self._ws.settimeout(0.05)
        try:
            while time.monotonic() < end:
                try:
                    self._record(json.loads(self._ws.recv()))
                except websocket.WebSocketTimeoutException:
                    pass
        finally:
            self._ws.settimeout(self.timeout)

    def open(self, url: str, settle: float = 0.5) -> None:
        """Navigate to ``url`` (a path is turned into a file URL), wait for its load event, then ``settle`` s."""
        if "://" not in url:
            url = Path(url).resolve().as_uri()
        self._events.clear()
        self.send("Page.navigate", url=url)
        deadline = time.monotonic() + self.timeout
        while not any(e.get("method") == "Page.loadEventFired" for e in self._events):
            if time.monotonic() > deadline:
                raise TimeoutError(f"{url} did not finish loading in {self.timeout:g} s")
            self._pump(0.1)
        self._pump(settle)

    def evaluate(self, expression: str):
        """The value of a JavaScript expression in the page (promises awaited)."""
        r = self.send("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(
                f"JavaScript error: {r['exceptionDetails'].get('exception', {}).get('description', r['exceptionDetails'])}"
            )
        return r["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 20.0, interval: float = 0.2):
        """Poll ``expression`` until it is truthy; return its value (TimeoutError after ``timeout`` s)."""
        deadline = time.monotonic() + timeout
        while True:
            v = self.evaluate(expression)
            if v:
                return v
            if time.monotonic() > deadline:
                raise TimeoutError(f"timed out after {timeout:g} s waiting for {expression}")
            self._pump(interval)

    def screenshot(self, path=None, full_page: bool = False) -> np.ndarray:
        """A PNG screenshot of the viewport (or the whole page), written to ``path`` if given; returns
        the ``(h, w, channels)`` pixels in [0, 1]."""
        import matplotlib.image

        params = {"format": "png"}
        if full_page:
            m = self.send("Page.getLayoutMetrics")["cssContentSize"]
            params.update(
                captureBeyondViewport=True,
                clip={"x": 0, "y": 0, "width": m["width"], "height": min(m["height"], 16000), "scale": 1},
            )
        data = base64.b64decode(self.send("Page.captureScreenshot", **params)["data"])
        if path is not None:
            Path(path).parent.mkdir(parents=True, exist_ok=True)
            Path(path).write_bytes(data)
        return matplotlib.image.imread(io.BytesIO(data), format="png")
