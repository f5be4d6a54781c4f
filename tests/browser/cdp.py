"""A small client for Chromium's DevTools protocol over a pipe
(--remote-debugging-pipe: commands on the browser's fd 3, replies and
events on its fd 4, each message JSON ended by a NUL byte), so the browser
tests need no WebSocket library and no driver package.

    with Browser() as b:
        page = b.open("file:///tmp/x.html", width=1000, height=700)
        page.evaluate("1 + 1")          # -> 2
        png = page.screenshot()          # base64 PNG
        page.errors                      # console errors and uncaught exceptions
"""
import fcntl
import json
import os
import select
import shutil
import subprocess
import tempfile
import time

FLAGS = [
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--hide-scrollbars", "--mute-audio", "--remote-debugging-pipe",
]


def find_chromium():
    for name in ("chromium", "chromium-browser"):
        path = shutil.which(name)
        if path:
            return path
    return None


class Browser:
    def __init__(self, executable=None, timeout=60):
        self.executable = executable or find_chromium()
        self.timeout = timeout
        self.next_id = 0
        self.buffer = b""
        self.events = []

    def __enter__(self):
        self.profile = tempfile.mkdtemp(prefix="cairn_chromium_")
        to_browser_r, to_browser_w = os.pipe()
        from_browser_r, from_browser_w = os.pipe()
        # The child sees its pipe ends as fds 3 and 4; they are copied above
        # 4 first so that one dup2 cannot overwrite the other.
        child_in = fcntl.fcntl(to_browser_r, fcntl.F_DUPFD, 10)
        child_out = fcntl.fcntl(from_browser_w, fcntl.F_DUPFD, 10)

        def setup():
            os.dup2(child_in, 3)
            os.dup2(child_out, 4)

        self.process = subprocess.Popen(
            [self.executable, *FLAGS, "--user-data-dir=" + self.profile, "about:blank"],
            pass_fds=(3, 4, child_in, child_out), preexec_fn=setup,
            stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        for fd in (to_browser_r, from_browser_w, child_in, child_out):
            os.close(fd)
        self.write_fd, self.read_fd = to_browser_w, from_browser_r
        return self

    def __exit__(self, *exc):
        try:
            self.call("Browser.close")
        except Exception:
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        os.close(self.write_fd)
        os.close(self.read_fd)
        shutil.rmtree(self.profile, ignore_errors=True)

    def cpu_seconds(self):
        """CPU time (user + system, s) used so far by the browser's processes,
        by kind: {'browser', 'gpu-process', 'renderer', 'utility', ...}
        (each child's --type; /proc, Linux only)."""
        tick = os.sysconf("SC_CLK_TCK")
        children, out = {}, {}
        for entry in os.listdir("/proc"):
            if not entry.isdigit():
                continue
            try:
                with open("/proc/%s/stat" % entry) as f:
                    stat = f.read()
                with open("/proc/%s/cmdline" % entry) as f:
                    args = f.read().replace("\0", " ").split()  # Chromium rewrites its title: spaces
            except OSError:
                continue
            fields = stat[stat.rindex(")") + 2:].split()  # after "pid (name) "
            kind = next((a[len("--type="):] for a in args if a.startswith("--type=")), "browser")
            children.setdefault(int(fields[1]), []).append((int(entry), kind, (int(fields[11]) + int(fields[12])) / tick))
        stack = [self.process.pid]
        with open("/proc/%d/stat" % self.process.pid) as f:
            stat = f.read()
        fields = stat[stat.rindex(")") + 2:].split()
        out["browser"] = (int(fields[11]) + int(fields[12])) / tick
        while stack:
            for pid, kind, seconds in children.get(stack.pop(), []):
                out[kind] = out.get(kind, 0) + seconds
                stack.append(pid)
        return out

    def _read_message(self, deadline):
        while b"\0" not in self.buffer:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("no reply from Chromium")
            ready, _, _ = select.select([self.read_fd], [], [], left)
            if ready:
                chunk = os.read(self.read_fd, 1 << 20)
                if not chunk:
                    raise RuntimeError("Chromium closed the pipe")
                self.buffer += chunk
        message, self.buffer = self.buffer.split(b"\0", 1)
        return json.loads(message)

    def call(self, method, params=None, session=None, timeout=None):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = session
        os.write(self.write_fd, json.dumps(message).encode() + b"\0")
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            reply = self._read_message(deadline)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError(method + ": " + reply["error"].get("message", str(reply["error"])))
                return reply.get("result", {})
            if "method" in reply:
                self.events.append(reply)

    def wait_event(self, method, session, timeout=None):
        deadline = time.monotonic() + (timeout or self.timeout)
        while True:
            for i, e in enumerate(self.events):
                if e["method"] == method and e.get("sessionId") == session:
                    return self.events.pop(i)
            reply = self._read_message(deadline)
            if "method" in reply:
                self.events.append(reply)

    def open(self, url, width=1000, height=700):
        target = self.call("Target.createTarget", {"url": "about:blank"})["targetId"]
        session = self.call("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
        page = Page(self, session)
        for domain in ("Runtime", "Log", "Page"):
            self.call(domain + ".enable", session=session)
        self.call("Emulation.setDeviceMetricsOverride",
                  {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False}, session)
        self.call("Page.navigate", {"url": url}, session)
        self.wait_event("Page.loadEventFired", session)
        return page


class Page:
    def __init__(self, browser, session):
        self.browser = browser
        self.session = session

    @property
    def errors(self):
        """Console errors, uncaught exceptions and error log entries so far."""
        out = []
        for e in self.browser.events:
            if e.get("sessionId") != self.session:
                continue
            p = e.get("params", {})
            if e["method"] == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                out.append("console." + p["type"] + ": " + " ".join(str(a.get("value", a.get("description", ""))) for a in p.get("args", [])))
            elif e["method"] == "Runtime.exceptionThrown":
                d = p.get("exceptionDetails", {})
                out.append("exception: " + d.get("exception", {}).get("description", d.get("text", "")))
            elif e["method"] == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                out.append("log: " + p["entry"].get("text", ""))
        return out

    def evaluate(self, expression, timeout=None):
        result = self.browser.call("Runtime.evaluate", {
            "expression": expression, "awaitPromise": True, "returnByValue": True}, self.session, timeout)
        if "exceptionDetails" in result:
            d = result["exceptionDetails"]
            raise RuntimeError(expression + ": " + d.get("exception", {}).get("description", d.get("text", "")))
        return result["result"].get("value")

    def wait_for(self, expression, timeout=30):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.evaluate(expression):
                return
            time.sleep(0.05)
        raise TimeoutError("timed out waiting for " + expression + "; page errors: " + "; ".join(self.errors))

    def screenshot(self):
        return self.browser.call("Page.captureScreenshot", {"format": "png"}, self.session)["data"]

    def click(self, x, y):
        for kind in ("mousePressed", "mouseReleased"):
            self.browser.call("Input.dispatchMouseEvent", {
                "type": kind, "x": x, "y": y, "button": "left", "buttons": 1 if kind == "mousePressed" else 0,
                "clickCount": 1}, self.session)
