"""Helpers of the 3-D view's tests: the command that writes the inputs, headless Chromium, PNG pixels.

Standard library only. Chromium (Debian's `chromium`, installed by scripts/install-deps.sh) renders
WebGL without a GPU through SwiftShader.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import struct
import subprocess
import tempfile
import zlib
from pathlib import Path
from typing import Dict, List, Optional, Tuple

import pytest

ROOT = Path(__file__).resolve().parents[2]


def _missing(what: str) -> None:
    """Skips the test where a tool is missing, fails under CI (where the scripts install it)."""
    if os.environ.get("CI"):
        pytest.fail(f"{what} (CI installs it: scripts/install-deps.sh, .ci/run)")
    pytest.skip(what)


def ffsr_optimize() -> str:
    """The command: $FFSR_OPTIMIZE, else the repository's build folders, else the PATH."""
    env = os.environ.get("FFSR_OPTIMIZE")
    if env:
        return env
    for folder in ("build-ci", "build", "build-run"):
        exe = ROOT / folder / "src" / "cli" / "ffsr-optimize"
        if exe.is_file() and os.access(exe, os.X_OK):
            return str(exe)
    found = shutil.which("ffsr-optimize")
    if not found:
        _missing("ffsr-optimize not found (set FFSR_OPTIMIZE or build it in build-ci/ or build/)")
    return found


def run_job(folder: Path, *args: str) -> Tuple[Path, Path]:
    """The main job with `args`, its --json and --csv in `folder`."""
    result, series = folder / "result.json", folder / "series.csv"
    cmd = [ffsr_optimize(), *args, "--quiet", "--json", str(result), "--csv", str(series)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, f"{' '.join(cmd)}: exit {p.returncode}\n{p.stderr}"
    return result, series


def chromium() -> str:
    for name in ("chromium", "chromium-browser", "google-chrome"):
        found = shutil.which(name)
        if found:
            return found
    _missing("chromium not found (Debian package chromium)")
    return ""


def browser_flags(profile: str) -> List[str]:
    flags = ["--headless", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-first-run",
             "--disable-background-networking", "--disable-component-update", "--disable-sync",
             "--hide-scrollbars", f"--user-data-dir={profile}"]
    if os.geteuid() == 0:
        flags += ["--no-sandbox", "--disable-gpu-sandbox"]
    return flags


class Page:
    """What headless Chromium made of a page: its DOM after the scripts ran, a screenshot, the console."""

    def __init__(self, dom: str, png: Path, console: List[str]):
        self.dom = dom
        self.png = png
        self.console = console

    def summary(self) -> Dict:
        m = re.search(r'<pre id="ffsr-view-summary"[^>]*>(.*?)</pre>', self.dom, re.S)
        assert m, "the page has no summary element"
        text = m.group(1).replace("&quot;", '"').replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
        assert text.strip(), "the page wrote no summary (its scripts did not finish)"
        return json.loads(text)


def _summary_pending(dom: str) -> bool:
    """The page has a summary element its scripts have not filled yet."""
    m = re.search(r'<pre id="ffsr-view-summary"[^>]*>(.*?)</pre>', dom, re.S)
    return bool(m) and not m.group(1).strip()


def open_page(html: Path, shot: Path, width: int = 1280, height: int = 800, fragment: str = "",
              budget_ms: int = 8000) -> Page:
    """Opens `html` (a file) for `budget_ms` of virtual time; the DOM, a screenshot, the console lines.

    Headless Chromium's virtual time can run out while the page still compiles its three.js module on
    a loaded machine (--dump-dom then shows the summary element empty: the scripts had not finished,
    nothing failed). That case, and only that one, is opened again, up to three times, each with twice
    the budget; a page whose scripts wrote a summary (errors included) is taken as it is."""
    for attempt in range(3):
        with tempfile.TemporaryDirectory(prefix="ffsr-chromium-") as profile:
            cmd = [chromium(), *browser_flags(profile), "--enable-logging=stderr", "--v=0",
                   f"--virtual-time-budget={budget_ms << attempt}", f"--window-size={width},{height}",
                   f"--screenshot={shot}", "--dump-dom", html.resolve().as_uri() + fragment]
            p = subprocess.run(cmd, capture_output=True, text=True, timeout=180)
        assert p.returncode == 0, f"chromium: exit {p.returncode}\n{p.stderr[-3000:]}"
        if not _summary_pending(p.stdout):
            break
    console = [line for line in p.stderr.splitlines() if ":CONSOLE" in line]
    return Page(p.stdout, shot, console)


# --- PNG ------------------------------------------------------------------------------------------------


def png_pixels(path: Path) -> Tuple[int, int, int, bytes]:
    """Width, height, channels and the raw 8-bit pixels of a non-interlaced PNG (grey, RGB, RGBA)."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n", f"{path}: not a PNG"
    pos, idat, header = 8, b"", None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        chunk = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            header = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat += chunk
        pos += 12 + length
    assert header is not None, f"{path}: no IHDR"
    w, h, depth, colour, _, _, interlace = header
    assert depth == 8 and interlace == 0, f"{path}: depth {depth}, interlace {interlace} not read here"
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[colour]
    raw = zlib.decompress(idat)
    stride = w * channels
    out = bytearray(h * stride)
    prev = bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if f == 1:
                line[x] = (line[x] + a) & 255
            elif f == 2:
                line[x] = (line[x] + b) & 255
            elif f == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        out[y * stride:(y + 1) * stride] = line
        prev = line
    return w, h, channels, bytes(out)


def grey_statistics(path: Path, box: Optional[Tuple[int, int, int, int]] = None) -> Tuple[float, int]:
    """The variance of the grey level (0-255) and the number of distinct colours, over `box`
    (x0, y0, x1, y1) or the whole picture."""
    w, h, ch, px = png_pixels(path)
    x0, y0, x1, y1 = box or (0, 0, w, h)
    n, s, s2, colours = 0, 0.0, 0.0, set()
    for y in range(y0, y1, 2):
        row = y * w * ch
        for x in range(x0, x1, 2):
            i = row + x * ch
            rgb = px[i:i + 3] if ch >= 3 else px[i:i + 1] * 3
            g = 0.299 * rgb[0] + 0.587 * rgb[1] + 0.114 * rgb[2]
            n += 1
            s += g
            s2 += g * g
            colours.add(bytes(rgb))
    mean = s / n
    return s2 / n - mean * mean, len(colours)
