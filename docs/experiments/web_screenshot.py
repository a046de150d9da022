"""A screenshot of the web cockpit in Chromium: a ``collect web`` server for TASK, the page
opened with the invite, Space pressed, and the picture taken SECONDS later (hands off: the
aircraft flies its trim). Real time, so it differs a little from run to run.

    python docs/experiments/web_screenshot.py OUT.png --task approach [--seconds 8]

Needs the web extra, Playwright and Debian's Chromium (apt-get install chromium).
"""

from __future__ import annotations

import argparse
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("out", type=Path)
    p.add_argument("--task", default="approach")
    p.add_argument("--seconds", type=float, default=8.0)
    args = p.parse_args()
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        raise SystemExit("no Chromium: apt-get install chromium")
    from playwright.sync_api import sync_playwright

    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.Popen(
            [sys.executable, "-m", "gymfg_il.collect", "web", "--out", f"{tmp}/web", "--port",
             "0", "--pilots", "1", "--task", args.task],
            stdout=subprocess.PIPE, text=True,
            env={**os.environ, "HF_HUB_OFFLINE": "1", "PYTHONUNBUFFERED": "1"},
        )  # fmt: skip
        assert proc.stdout is not None
        link = ""
        for line in proc.stdout:
            found = re.search(r"invite pilot-1: (\S+)", line)
            if found:
                link = found.group(1)
            if "waiting for pilots" in line:
                break
        try:
            with sync_playwright() as pw:
                browser = pw.chromium.launch(executable_path=chromium, args=["--no-sandbox"])
                page = browser.new_page(viewport={"width": 1280, "height": 860}, bypass_csp=True)
                page.goto(link)
                page.wait_for_function("document.getElementById('state').textContent"
                                       ".startsWith('flying')")  # fmt: skip
                page.keyboard.press("Space")
                time.sleep(args.seconds)
                args.out.parent.mkdir(parents=True, exist_ok=True)
                page.screenshot(path=str(args.out))
                browser.close()
        finally:
            proc.send_signal(signal.SIGINT)
            proc.wait(120)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
