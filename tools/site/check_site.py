#!/usr/bin/env python3
"""The course website's check (tools/site.sh --check; tools/test.sh's last stage): the site used as a
person would, in Debian's Chromium, headless, with the network off.

1. links: every href and src of every page in the site (and every url() of its style sheets) is a file
   of the site (an #anchor: an id or name in that page) or a link to another host that a reader
   follows by choice (<a href="https://…">, listed); a page that would load anything from another host
   (a script, a style sheet, an image, a frame, a font) fails.
2. pages: Chromium (driven over its DevTools protocol, stdlib only) opens every page from file://;
   each must load with no request for anything but file: and data: URLs and no console error or
   uncaught exception.
3. search: on a chapter page, typing a term of a chapter's body text ("Rayleigh") into the search box
   lists a link to that chapter's page (10_linear_dynamics.html), and following it opens the page.
4. the gallery: a gallery page's embedded scene page (the first one built) draws the body at its
   first and last frame (pixels in colour, as tools/check_web_page.py counts them) and the body moved
   between the two.

Exit 0: passed; 1: failed (each failure printed); 77: no chromium.
"""
import argparse
import base64
import html.parser
import json
import os
import pathlib
import re
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.parse

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1]))
from check_web_page import body_pixels  # noqa: E402  (the scene page's own browser test)

SKIP = 77
WIDTH, HEIGHT = 1280, 900


class Links(html.parser.HTMLParser):
    """A page's ids and its references: [(tag, attribute, value)]."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.ids, self.references = set(), []

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        for key in ("id", "name"):
            if attrs.get(key):
                self.ids.add(attrs[key])
        for key in ("href", "src", "poster"):
            if attrs.get(key) is not None:
                self.references.append((tag, key, attrs[key], attrs.get("rel", "")))


def check_links(site):
    """The failures of the link check, and (references checked, links to other hosts)."""
    pages, failures, external, checked = {}, [], set(), 0
    for page in site.rglob("*.html"):
        parser = Links()
        parser.feed(page.read_text(encoding="utf-8", errors="replace"))
        pages[page.resolve()] = parser
    for page, parser in sorted(pages.items()):
        where = page.relative_to(site.resolve())
        for tag, key, value, rel in parser.references:
            checked += 1
            target = value.strip()
            if re.match(r"^(https?:)?//", target):
                if tag == "a":
                    external.add(target)
                else:
                    failures.append(f"{where}: <{tag} {key}={target!r}> loads from another host")
                continue
            if re.match(r"^(mailto|data|javascript|blob):", target) or target == "":
                continue
            path, _, fragment = target.partition("#")
            path = urllib.parse.unquote(path.split("?")[0])
            resolved = (page.parent / path).resolve() if path else page
            if not resolved.exists():
                failures.append(f"{where}: <{tag} {key}={target!r}>: no such file")
            elif resolved.is_dir():
                failures.append(f"{where}: <{tag} {key}={target!r}>: a folder (a browser shows a listing on file://)")
            elif fragment and resolved in pages and urllib.parse.unquote(fragment) not in pages[resolved].ids \
                    and not re.match(r"^(frame|positions)=", fragment):
                failures.append(f"{where}: <{tag} {key}={target!r}>: no id {fragment!r} in {resolved.name}")
    for sheet in site.rglob("*.css"):
        for url in re.findall(r"url\(\s*['\"]?([^'\")]+)", sheet.read_text(encoding="utf-8", errors="replace")):
            checked += 1
            if re.match(r"^(https?:)?//", url):
                failures.append(f"{sheet.relative_to(site)}: url({url}) loads from another host")
            elif not url.startswith("data:") and not (sheet.parent / url.split("#")[0].split("?")[0]).exists():
                failures.append(f"{sheet.relative_to(site)}: url({url}): no such file")
    return failures, checked, sorted(external), len(pages)


class DevTools:
    """A minimal client of Chromium's DevTools protocol over a WebSocket (RFC 6455, stdlib only)."""

    def __init__(self, url):
        parsed = urllib.parse.urlparse(url)
        self.socket = socket.create_connection((parsed.hostname, parsed.port), timeout=60)
        key = base64.b64encode(os.urandom(16)).decode()
        self.socket.sendall((f"GET {parsed.path} HTTP/1.1\r\nHost: {parsed.hostname}:{parsed.port}\r\n"
                             f"Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                             "Sec-WebSocket-Version: 13\r\n\r\n").encode())
        reply = b""
        while b"\r\n\r\n" not in reply:
            reply += self.socket.recv(4096)
        head, _, self.buffer = reply.partition(b"\r\n\r\n")
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise RuntimeError(f"DevTools refused the WebSocket: {head[:200]!r}")
        self.next_id, self.events = 0, []

    def _read(self, n):
        while len(self.buffer) < n:
            chunk = self.socket.recv(1 << 20)
            if not chunk:
                raise RuntimeError("DevTools closed the connection")
            self.buffer += chunk
        data, self.buffer = self.buffer[:n], self.buffer[n:]
        return data

    def _message(self):
        text = b""
        while True:
            first, second = self._read(2)
            length = second & 127
            if length == 126:
                length = struct.unpack(">H", self._read(2))[0]
            elif length == 127:
                length = struct.unpack(">Q", self._read(8))[0]
            text += self._read(length)
            if first & 0x80:
                return json.loads(text)

    def send(self, method, session=None, **params):
        """Sends a command and returns its result, keeping the events that arrive meanwhile."""
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params}
        if session:
            message["sessionId"] = session
        payload, mask = json.dumps(message).encode(), os.urandom(4)
        header = bytes([0x81]) + (bytes([0x80 | len(payload)]) if len(payload) < 126 else
                                  bytes([0x80 | 126]) + struct.pack(">H", len(payload)) if len(payload) < 65536 else
                                  bytes([0x80 | 127]) + struct.pack(">Q", len(payload)))
        self.socket.sendall(header + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(payload)))
        while True:
            reply = self._message()
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(f"{method}: {reply['error']}")
                return reply.get("result", {})
            self.events.append(reply)

    def wait_for(self, method, seconds):
        """The first event `method` (kept events first), or None after `seconds`."""
        deadline = time.time() + seconds
        while time.time() < deadline:
            for i, event in enumerate(self.events):
                if event.get("method") == method:
                    return self.events.pop(i)
            self.socket.settimeout(max(0.05, deadline - time.time()))
            try:
                self.events.append(self._message())
            except (socket.timeout, TimeoutError):
                break
            finally:
                self.socket.settimeout(60)
        return None


class Browser:
    """Headless Chromium with the network off, one tab driven over DevTools."""

    def __init__(self, chromium, profile):
        self.process = subprocess.Popen(
            [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
             "--enable-unsafe-swiftshader", "--proxy-server=127.0.0.1:9", "--host-resolver-rules=MAP * ~NOTFOUND",
             "--hide-scrollbars", "--no-first-run", "--disable-background-networking", "--disable-extensions",
             "--disable-component-update", "--disable-sync", "--remote-debugging-port=0", f"--user-data-dir={profile}",
             f"--window-size={WIDTH},{HEIGHT}", "about:blank"],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = pathlib.Path(profile) / "DevToolsActivePort"
        for _ in range(300):
            if port_file.exists() and len(port_file.read_text().split("\n")) >= 2:
                break
            time.sleep(0.1)
        port, path = port_file.read_text().split("\n")[:2]
        self.devtools = DevTools(f"ws://127.0.0.1:{port}{path}")
        target = self.devtools.send("Target.createTarget", url="about:blank")["targetId"]
        self.session = self.devtools.send("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
        for domain in ("Page", "Runtime", "Network", "Log"):
            self.call(f"{domain}.enable")
        self.call("Emulation.setDeviceMetricsOverride", width=WIDTH, height=HEIGHT, deviceScaleFactor=1, mobile=False)

    def call(self, method, **params):
        return self.devtools.send(method, self.session, **params)

    def open(self, url, seconds=20):
        """Opens url; returns (loaded in time, [requests not to file: or data:], [console errors])."""
        self.devtools.events.clear()
        self.call("Page.navigate", url=url)
        loaded = self.devtools.wait_for("Page.loadEventFired", seconds) is not None
        self.settle(0.05)
        requests, errors = [], []
        for event in self.devtools.events:
            method, params = event.get("method"), event.get("params", {})
            if method == "Network.requestWillBeSent":
                request = params["request"]["url"]
                if not re.match(r"^(file|data|blob|about):", request):
                    requests.append(request)
            elif method == "Runtime.consoleAPICalled" and params.get("type") in ("error", "assert"):
                errors.append(" ".join(str(a.get("value", a.get("description", ""))) for a in params.get("args", [])))
            elif method == "Runtime.exceptionThrown":
                details = params["exceptionDetails"]
                errors.append(details.get("exception", {}).get("description", details.get("text", "exception")))
            elif method == "Log.entryAdded" and params["entry"]["level"] == "error":
                errors.append(f"{params['entry'].get('text')} ({params['entry'].get('url', '')})")
            elif method == "Network.loadingFailed" and not params.get("canceled"):
                errors.append(f"a request failed: {params.get('errorText')}")
        return loaded, requests, errors

    def settle(self, seconds):
        """Collects events for `seconds`."""
        self.devtools.wait_for("(none)", seconds)

    def evaluate(self, expression):
        result = self.call("Runtime.evaluate", expression=expression, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression[:80]}…: {result['exceptionDetails'].get('text')}")
        return result["result"].get("value")

    def screenshot(self, path, clip):
        data = self.call("Page.captureScreenshot", format="png", clip={**clip, "scale": 1})["data"]
        pathlib.Path(path).write_bytes(base64.b64decode(data))

    def close(self):
        try:
            self.devtools.send("Browser.close")
        except (RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()


def check_pages(browser, site, pages, out):
    """Opens every page: one at a time those with scripts (the docs pages, the gallery's, the players);
    the rendered source files (no script: a style sheet and links) 60 at a time, as the frames of a
    page written into out, so that a thousand of them take seconds."""
    failures = []
    started = time.time()
    scripted = [p for p in pages if "<script" in p.read_text(encoding="utf-8", errors="replace")]
    plain = [p for p in pages if p not in scripted]
    for k in range(0, len(plain), 60):
        batch = plain[k:k + 60]
        harness = out / f"pages_{k // 60}.html"
        harness.write_text("<!DOCTYPE html><title>pages</title>" + "".join(
            f'<iframe src="{p.as_uri()}" width="200" height="100"></iframe>' for p in batch), encoding="utf-8")
        loaded, requests, errors = browser.open(harness.as_uri(), seconds=60)
        if not loaded:
            failures.append(f"{batch[0].relative_to(site)} … {batch[-1].relative_to(site)}: did not finish loading")
        failures += [f"one of {batch[0].relative_to(site)} … {batch[-1].relative_to(site)}: a request leaves the "
                     f"machine: {r}" for r in requests]
        failures += [f"one of {batch[0].relative_to(site)} … {batch[-1].relative_to(site)}: console error: {e}"
                     for e in errors]
    for page in scripted:
        loaded, requests, errors = browser.open(page.as_uri(), seconds=30 if page.stat().st_size > 1e6 else 15)
        where = page.relative_to(site)
        if not loaded:
            failures.append(f"{where}: did not finish loading")
        failures += [f"{where}: a request leaves the machine: {r}" for r in requests]
        failures += [f"{where}: console error: {e}" for e in errors]
    print(f"pages: {len(pages)} opened in Chromium from file:// ({len(scripted)} with scripts one by one, "
          f"{len(plain)} without in frames) in {time.time() - started:.1f} s")
    return failures


def check_search(browser, site, term, chapter):
    """Types `term` into a page's search box: a result must link to `chapter`, and following it opens it."""
    browser.open((site / "index.html").as_uri())
    links = browser.evaluate(f"""(async () => {{
        const input = document.getElementById("fem-search-input");
        if (!input) return null;
        input.focus(); input.value = {json.dumps(term)}; input.dispatchEvent(new Event("input"));
        for (let i = 0; i < 100; ++i) {{
          const found = document.querySelectorAll("#fem-search-results a");
          if (found.length) return Array.from(found, (a) => a.href);
          await new Promise((r) => setTimeout(r, 50));
        }}
        return [];
    }})()""")
    if links is None:
        return ["search: the home page has no search box (#fem-search-input)"]
    hits = [link for link in links if link.split("#")[0].endswith("/" + chapter)]
    print(f"search {term!r}: {len(links)} results, {len(hits)} on {chapter} (first: {hits[0] if hits else '-'})")
    if not hits:
        return [f"search: {term!r} lists no link to {chapter} (results: {links[:5]})"]
    loaded, _, errors = browser.open(hits[0])
    if not loaded or errors or not browser.evaluate("location.pathname").endswith("/" + chapter):
        return [f"search: the result {hits[0]} did not open ({errors})"]
    return []


def check_gallery(browser, site, out):
    """A gallery page's embedded player draws the body at its first and last frame, and it moved."""
    for page in sorted((site / "gallery").glob("*.html")):
        text = page.read_text(encoding="utf-8")
        player = re.search(r'<iframe src="([^"#]+\.html)"', text)
        if player and (page.parent / player.group(1)).exists() and 'id="fem-data"' not in text:
            break
    else:
        return ["gallery: no gallery page embeds a scene page (tools/run_course.sh scenes, or tools/site.sh --quick-scene)"]
    scene = (page.parent / player.group(1)).read_text(encoding="utf-8")
    start = scene.index('id="fem-data">') + len('id="fem-data">')
    frames = json.loads(scene[start:scene.index("</script>", start)])["frames"]
    shots = {}
    for frame in (0, frames - 1):
        browser.open(page.as_uri())
        box = browser.evaluate(f"""(async () => {{
            const frame = document.querySelector(".fem-player iframe"), header = document.querySelector(".md-header");
            scrollTo(0, frame.getBoundingClientRect().top + scrollY - (header ? header.offsetHeight + 8 : 0));
            frame.loading = "eager";
            await new Promise((r) => {{ frame.onload = r; frame.src = {json.dumps(player.group(1))} + "?shot={frame}#frame={frame}"; }});
            await new Promise((r) => setTimeout(r, 1500));
            const b = frame.getBoundingClientRect();
            return {{ x: b.left + scrollX, y: b.top + scrollY, width: b.width, height: b.height }};
        }})()""")
        shot = out / f"gallery_frame_{frame}.png"
        browser.screenshot(shot, box)
        shots[frame] = body_pixels(shot)
        print(f"gallery {page.name}, frame {frame}: {len(shots[frame])} body pixels ({shot}, {box['width']:.0f}×{box['height']:.0f})")
    failures = check_legend(browser, page.parent / player.group(1))
    first, last = shots[0], shots[frames - 1]
    if min(len(first), len(last)) < 1000:
        failures.append(f"gallery {page.name}: the embedded player draws no body in colour (fewer than 1000 pixels)")
    if len(first ^ last) < 0.05 * max(len(first), len(last), 1):
        failures.append(f"gallery {page.name}: the body looks the same at the first and last frame")
    return failures


def check_legend(browser, player):
    """The player's energy legend: an entry per series, none over the plot's frame, all in the window;
    a click on an entry hides its curve and a second click shows it again."""
    browser.open(player.as_uri() + "#frame=0")
    try:
        found = legend_layout(browser)
    except RuntimeError as error:
        return [f"{player.name}: no energy legend to check (#plot-frame, #series .entry): {error}"]
    print(f"legend of {player.name}: {found['entries']} entries for {found['series']} series, {found['over']} over the plot, "
          f"{found['outside']} outside the window; curves {found['before']} → {found['hidden']} hidden → {found['after']}")
    failures = []
    if found["entries"] != found["series"] or found["over"] or found["outside"]:
        failures.append(f"{player.name}: the energy legend overprints the plot or misses series ({found})")
    if not found["before"] == found["after"] == found["hidden"] + 1 == found["series"]:
        failures.append(f"{player.name}: a click on a legend entry does not hide and show its curve ({found})")
    return failures


def legend_layout(browser):
    """The open player's legend: entries, series, entries over the plot or outside the window, and the
    curves drawn before, while and after the first entry is clicked off."""
    return browser.evaluate("""(() => {
        const box = (e) => { const r = e.getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; };
        const frame = box(document.getElementById("plot-frame")), curves = () => document.querySelectorAll("#energy path").length;
        const entries = Array.from(document.querySelectorAll("#series .entry"));
        const over = entries.filter((e) => { const b = box(e); return b[0] < frame[2] && b[2] > frame[0] && b[1] < frame[3] && b[3] > frame[1]; });
        const outside = entries.filter((e) => { const b = box(e); return b[2] - b[0] < 1 || b[3] > innerHeight || b[2] > innerWidth; });
        const before = curves(); entries[0].click(); const hidden = curves(); entries[0].click();
        return { series: JSON.parse(document.getElementById("fem-data").textContent).energy.series.length,
                 entries: entries.length, over: over.length, outside: outside.length, before: before, hidden: hidden, after: curves() };
    })()""")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--site", default="site")
    parser.add_argument("--out", default="build/site_check", help="a folder for the browser's profile and screenshots")
    parser.add_argument("--chromium", default="chromium")
    parser.add_argument("--search", default="Rayleigh", help="a term of a chapter's body text")
    parser.add_argument("--search-page", default="10_linear_dynamics.html", help="the page the term must find")
    parser.add_argument("--screenshots", help="also save the home page, a chapter page and a gallery page here")
    args = parser.parse_args()
    site, out = pathlib.Path(args.site).resolve(), pathlib.Path(args.out).resolve()
    if not (site / "index.html").exists():
        print(f"error: {site}/index.html does not exist: tools/site.sh writes the site")
        return 1
    failures, checked, external, page_count = check_links(site)
    print(f"links: {checked} references in {page_count} pages checked; {len(external)} links to other hosts "
          f"(followed by choice: {', '.join(external[:4])}{' …' if len(external) > 4 else ''})")
    chromium = shutil.which(args.chromium)
    if chromium is None:
        print(f"SKIPPED the browser checks: no {args.chromium} (tools/setup.sh installs Debian's chromium)")
        for failure in failures:
            print("FAILED: " + failure)
        return 1 if failures else SKIP
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    browser = Browser(chromium, tempfile.mkdtemp(prefix="profile", dir=out))
    try:
        failures += check_pages(browser, site, sorted(site.rglob("*.html")), out)
        failures += check_search(browser, site, args.search, args.search_page)
        failures += check_gallery(browser, site, out)
        if args.screenshots:
            take_screenshots(browser, site, pathlib.Path(args.screenshots))
    finally:
        browser.close()
    for failure in failures[:200]:
        print("FAILED: " + failure)
    if len(failures) > 200:
        print(f"… and {len(failures) - 200} more")
    print("site check: " + ("FAILED" if failures else "passed"))
    return 1 if failures else 0


def take_screenshots(browser, site, folder):
    """What a reader sees, saved into folder: site_home.png, site_chapter.png (chapter 10), site_search.png
    (chapter 10 with "Rayleigh damping" typed into the search box), site_gallery.png (a scene's page,
    one with a video if any) and site_gallery_index.png."""
    folder.mkdir(parents=True, exist_ok=True)
    players = [p for p in sorted((site / "gallery").glob("*.html")) if "fem-player" in p.read_text(encoding="utf-8")]
    gallery = next((p for p in players if "<video" in p.read_text(encoding="utf-8")), players[0] if players else None)
    shots = [("home", site / "index.html", ""), ("chapter", site / "10_linear_dynamics.html", ""),
             ("search", site / "10_linear_dynamics.html", "Rayleigh damping"),
             ("gallery", gallery or site / "gallery" / "index.html", ""), ("gallery_index", site / "gallery" / "index.html", "")]
    for name, page, query in shots:
        browser.open(page.as_uri())
        browser.evaluate(f"""(async () => {{
            const f = document.querySelector(".fem-player iframe");
            if (f) {{ f.loading = "eager"; await new Promise((r) => setTimeout(r, 2500)); }}
            const query = {json.dumps(query)}, input = document.getElementById("fem-search-input");
            if (query && input) {{ input.focus(); input.value = query; input.dispatchEvent(new Event("input"));
                                   await new Promise((r) => setTimeout(r, 500)); }}
        }})()""")
        browser.screenshot(folder / f"site_{name}.png", {"x": 0, "y": 0, "width": WIDTH, "height": HEIGHT})
        print(f"screenshot: {folder / f'site_{name}.png'} ({page.relative_to(site)}{', searching ' + repr(query) if query else ''})")


if __name__ == "__main__":
    sys.exit(main())
