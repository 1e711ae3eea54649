"""Headless Chromium (Debian's chromium and chromium-driver, installed by scripts/setup.sh) driven by
Selenium, for the tests that open the HTML reports: the network is blocked (Chrome DevTools'
Network.setBlockedURLs for every scheme but file and data, and no host name resolves), and every request
the page makes is logged, so a test can show that a page fetched nothing."""

import json
import shutil
import tempfile
from contextlib import contextmanager
from pathlib import Path

import pytest

CHROMIUM, DRIVER = Path("/usr/bin/chromium"), Path("/usr/bin/chromedriver")
FLAGS = ("--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync", "--window-size=1280,1600",
         "--enable-unsafe-swiftshader", "--host-resolver-rules=MAP * ~NOTFOUND")
BLOCKED = ["http://*", "https://*", "ws://*", "wss://*", "ftp://*"]


@contextmanager
def chromium():
    """A Selenium driver of headless Chromium with the network blocked (skips where it is missing)."""
    if not (CHROMIUM.is_file() and DRIVER.is_file()):
        pytest.skip("Debian's chromium and chromium-driver are not installed (scripts/setup.sh installs them)")
    webdriver = pytest.importorskip("selenium.webdriver",
                                    reason="selenium is a test dependency (pip install -e .[test])")
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="pcbdyn-chromium-")
    opts = webdriver.ChromeOptions()
    opts.binary_location = str(CHROMIUM)
    for flag in (*FLAGS, f"--user-data-dir={profile}"):
        opts.add_argument(flag)
    opts.set_capability("goog:loggingPrefs", {"performance": "ALL"})
    driver = webdriver.Chrome(service=Service(str(DRIVER)), options=opts)
    driver.execute_cdp_cmd("Network.enable", {})
    driver.execute_cdp_cmd("Network.setBlockedURLs", {"urls": BLOCKED})
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def requests_made(driver) -> list:
    """The network URLs (http, https, ws, wss, ftp) the browser asked for since the last call (each
    was blocked); the browser's own chrome: pages and the pages' file: and data: URLs are not network."""
    urls = []
    for entry in driver.get_log("performance"):
        msg = json.loads(entry["message"])["message"]
        if msg.get("method") == "Network.requestWillBeSent":
            urls.append(msg["params"]["request"]["url"])
    return [u for u in urls if u.split(":", 1)[0] in ("http", "https", "ws", "wss", "ftp")]
