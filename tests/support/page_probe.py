#!/usr/bin/python3
"""Drives Debian's headless Chromium over the DevTools protocol (--remote-debugging-pipe: JSON
messages ended by NUL on file descriptors 3 and 4, no extra package) to check the operator page
as people meet it: at each window size the page's layout (nothing wider than the window, the
3-D view the size of its box, the size column of the history in view) with a full-page
screenshot; the page while a parcel is measured (live panel, previous result dimmed and
labelled); and a history row opened.

usage: page_probe.py URL OUT_DIR STEP...
STEP is WxH (load the page at that size), resize:WxH (the same page, the window resized),
measure (click Measure, watch the live panel, wait for the result) or open:ID (select that
history row). Prints one JSON object per step on stdout; screenshots are OUT_DIR/<n>.png."""
import base64
import json
import os
import struct
import subprocess
import sys
import time

PROBE = r"""JSON.stringify((() => {
  const W = window.innerWidth, $ = (id) => document.getElementById(id);
  const box = (el) => { const r = el.getBoundingClientRect(); return {left: r.left, right: r.right, width: r.width, height: r.height}; };
  const canvas = document.querySelector('#view canvas');
  const size = [...document.querySelectorAll('#history-table th')].find((th) => th.textContent.startsWith('L '));
  const probeRow = $('history-table').insertRow();
  probeRow.className = 'failed';
  const failedBackground = getComputedStyle(probeRow).backgroundColor;
  probeRow.remove();
  return {
    inner_width: W, scroll_width: document.documentElement.scrollWidth,
    sections: [...document.querySelectorAll('section')].filter((s) => !s.hidden).map((s) => ({id: s.id, ...box(s)})),
    view: box($('view')),
    canvas: canvas ? {width: canvas.clientWidth, height: canvas.clientHeight, points: +canvas.dataset.points, lit: +canvas.dataset.litPixels} : null,
    size_column: size ? box(size) : null,
    history_ids: [...document.querySelectorAll('#history-table tr[data-id]')].map((tr) => tr.dataset.id),
    shown_rows: [...document.querySelectorAll('#history-table tr.shown')].map((tr) => tr.dataset.id),
    failed_row_background: failedBackground,
    last_id: $('last-id').textContent, last_label: $('last-label').textContent,
    last_note: $('last-note').textContent, last_dimmed: $('last').classList.contains('previous'),
    previous_note: $('previous-note').hidden ? null : $('previous-note').textContent,
    live: $('live').hidden ? null : {id: $('live-id').textContent, text: $('live-text').textContent, bar: $('live-bar').style.width},
    back_shown: !$('back-to-latest').hidden, clock_note: $('clock-note').textContent,
    calibration: $('calibration-facts').textContent, history_text: $('history-table').textContent,
    billing: $('billing').hidden ? null : $('billing').textContent,
    dims: $('dims').textContent,
    audit: $('audit-facts').textContent,
  };
})())"""


class Chromium:
    def __init__(self):
        to_child, self.to_browser = os.pipe()
        self.from_browser, from_child = os.pipe()

        def fds():
            # Through copies: a pipe's own number may already be 3 or 4, and dup2 onto itself
            # would leave it close-on-exec.
            reading, writing = os.dup(to_child), os.dup(from_child)
            os.dup2(reading, 3)
            os.dup2(writing, 4)

        self.proc = subprocess.Popen(
            ["chromium", "--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
             "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-first-run",
             "--hide-scrollbars", "--remote-debugging-pipe", "about:blank"],
            preexec_fn=fds, close_fds=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        os.close(to_child)
        os.close(from_child)
        self.buffer, self.next_id, self.session = b"", 0, None

    def call(self, method, **params):
        self.next_id += 1
        message = {"id": self.next_id, "method": method, "params": params}
        if self.session and not method.startswith("Target."):
            message["sessionId"] = self.session
        os.write(self.to_browser, json.dumps(message).encode() + b"\0")
        while True:
            while b"\0" not in self.buffer:
                chunk = os.read(self.from_browser, 1 << 20)
                if not chunk:
                    raise RuntimeError("chromium closed the pipe")
                self.buffer += chunk
            raw, self.buffer = self.buffer.split(b"\0", 1)
            reply = json.loads(raw)
            if reply.get("id") == self.next_id:
                if "error" in reply:
                    raise RuntimeError("%s: %s" % (method, reply["error"]))
                return reply["result"]

    def evaluate(self, expression):
        return self.call("Runtime.evaluate", expression=expression, returnByValue=True,
                         awaitPromise=True)["result"].get("value")

    def wait_for(self, expression, seconds=30.0):
        end = time.time() + seconds
        while time.time() < end:
            if self.evaluate(expression):
                return True
            time.sleep(0.1)
        return False


# The canvas fills the view again at the window width given, the cloud drawn on it.
FITTED = ("(() => { const c = document.querySelector('#view canvas'); "
          "const v = document.getElementById('view').getBoundingClientRect(); "
          "return window.innerWidth === %d && c !== null && Math.abs(c.clientWidth - v.width) <= 1 "
          "&& Math.abs(c.clientHeight - v.height) <= 1 && +c.dataset.litPixels > 500; })()")


def screenshot(browser, path):
    metrics = browser.call("Page.getLayoutMetrics")["cssContentSize"]
    shot = browser.call("Page.captureScreenshot", format="png", captureBeyondViewport=True,
                        clip={"x": 0, "y": 0, "width": metrics["width"],
                              "height": metrics["height"], "scale": 1})
    data = base64.b64decode(shot["data"])
    with open(path, "wb") as f:
        f.write(data)
    width, height = struct.unpack(">II", data[16:24])  # the PNG's IHDR
    return {"file": path, "width": width, "height": height}


def size(browser, text):
    width, height = (int(v) for v in text.split("x"))
    browser.call("Emulation.setDeviceMetricsOverride", width=width, height=height,
                 deviceScaleFactor=1, mobile=width < 800)


def main():
    url, out, steps = sys.argv[1], sys.argv[2], sys.argv[3:]
    browser = Chromium()
    target = browser.call("Target.createTarget", url="about:blank")["targetId"]
    browser.session = browser.call("Target.attachToTarget", targetId=target, flatten=True)["sessionId"]
    # The cloud drawn: a canvas with more lit pixels than its background's edges (a "0" from a
    # draw before the canvas had its size is not drawn yet).
    drawn = "+((document.querySelector('#view canvas') || {dataset: {}}).dataset.litPixels || 0) > 500"
    # And the history loaded: its header row is made when the list arrives (the cloud, fetched
    # beside it, may be drawn first on a loaded machine).
    loaded = drawn + " && document.querySelector('#history-table th') !== null"
    for n, step in enumerate(steps):
        result = {"step": step}
        if step[0].isdigit():
            size(browser, step)
            browser.call("Page.navigate", url=url)
            time.sleep(0.3)
            result["loaded"] = browser.wait_for(loaded)
        elif step.startswith("resize:"):
            size(browser, step[len("resize:"):])
            # The ResizeObserver redraws: until the canvas has the view's new size and the cloud
            # is drawn on it (a loaded machine takes longer than any fixed pause).
            result["redrawn"] = browser.wait_for(FITTED % int(step.split(":")[1].split("x")[0]), 15)
            time.sleep(0.3)
        elif step == "measure":
            before = browser.evaluate("document.getElementById('last-id').textContent")
            browser.evaluate("document.getElementById('measure').click()")
            # The panel opens as the measurement is claimed and names it a moment later, once
            # its id is reserved in the store.
            result["live_seen"] = browser.wait_for(
                "!document.getElementById('live').hidden && "
                "document.getElementById('live-id').textContent !== ''", 10)
            result["during"] = json.loads(browser.evaluate(PROBE))
            result["during_screenshot"] = screenshot(browser, os.path.join(out, "%d-during.png" % n))
            result["finished"] = browser.wait_for(
                "document.getElementById('live').hidden && document.getElementById('last-id')"
                ".textContent !== %s" % json.dumps(before), 60)
            time.sleep(0.5)
        elif step.startswith("open:"):
            ident = step[len("open:"):]
            browser.evaluate("document.querySelector('#history-table tr[data-id=\"%s\"]').click()" % ident)
            result["opened"] = browser.wait_for(
                "document.querySelector('#view canvas[data-id=\"%s\"][data-lit-pixels]') !== null" % ident, 20)
        result["page"] = json.loads(browser.evaluate(PROBE))
        result["screenshot"] = screenshot(browser, os.path.join(out, "%d.png" % n))
        print(json.dumps(result), flush=True)
    browser.proc.kill()


if __name__ == "__main__":
    main()
