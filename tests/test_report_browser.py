"""The combined report as a reader sees it: opened in a real headless Chromium.

The report is built from a scratch copy of the repository with ``config/test.yaml``
(never in the real ``results/``), then served as static files from ``report/`` alone
by ``python -m http.server``'s handler, which also proves that the report needs
nothing outside its folder. Checks: every image loads, every internal link
resolves (files and anchors), no console errors and no network request leaves
the report, the scorecard equals the claims tables, and a screenshot of the top
is saved as ``report/screenshot.png`` (git-ignored; ``REPORT_SCREENSHOT`` overrides the path).

Needs ``/usr/bin/chromium`` and ``chromedriver`` (Debian packages ``chromium``
and ``chromium-driver``, installed in CI by ``.ci/setup.d/10-browser.sh``) and the
``selenium`` package; skips with the reason when one is missing.
"""

from __future__ import annotations

import contextlib
import functools
import http.server
import os
import shutil
import tempfile
import threading
import time
import urllib.parse
import urllib.request
from pathlib import Path

import pandas as pd
import pytest

from netrepro.judging.verdicts import VERDICTS  # every category of the vocabulary is a scorecard column

from .conftest import run_snakemake

ROOT = Path(__file__).resolve().parents[1]
CHROMIUM_FLAGS = ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                  "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-dev-shm-usage",
                  "--window-size=1280,1600")

# The small configuration of the workflow test (NETREPRO_REPORT_CONFIG overrides it, with NETREPRO_BUILT_REPORT).
CONFIG = os.environ.get("NETREPRO_REPORT_CONFIG", "config/test.yaml")

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]


def _find(*names):
    for name in names:
        path = shutil.which(name)
        if path:
            return path
    return None


def snakemake(workdir, *args, timeout=900):
    return run_snakemake(workdir, *args, config=CONFIG, timeout=timeout)


@pytest.fixture(scope="module")
def built_report(built_repo):
    """The session's scratch repository with the full report built on the test configuration."""
    return built_repo


# ----------------------------------------------------------------------------- browser
class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):  # keep pytest output clean
        pass

    def handle(self):  # the browser may drop a connection it no longer needs
        with contextlib.suppress(ConnectionError):
            super().handle()


@contextlib.contextmanager
def serve(directory: Path):
    """Serve ``directory`` over HTTP on a free local port, as ``python -m http.server`` does."""
    handler = functools.partial(_QuietHandler, directory=str(directory))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


@pytest.fixture(scope="module")
def browser():
    chromium = _find("chromium", "chromium-browser", "google-chrome")
    driver_bin = _find("chromedriver")
    if chromium is None or driver_bin is None:
        pytest.skip("no Chromium/chromedriver installed (apt-get install chromium chromium-driver, "
                    "as .ci/setup.d/10-browser.sh does in CI)")
    webdriver = pytest.importorskip("selenium.webdriver", reason="selenium not installed (pip install -e '.[test]')")
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="chromium-profile-")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in CHROMIUM_FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(executable_path=driver_bin), options=options)
    driver.set_page_load_timeout(60)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def console_errors(driver) -> list[str]:
    return [f"{e['level']}: {e['message']}" for e in driver.get_log("browser") if e["level"] in ("SEVERE", "ERROR")]


def page_state(driver) -> dict:
    """Images, links, anchors and network requests of the loaded page."""
    return driver.execute_script("""
        const imgs = Array.from(document.images).map(i => ({
            src: i.getAttribute('src').slice(0, 60), complete: i.complete, width: i.naturalWidth}));
        const links = Array.from(document.querySelectorAll('a[href]')).map(a => ({
            raw: a.getAttribute('href'), url: a.href}));
        const ids = Array.from(document.querySelectorAll('[id]')).map(e => e.id);
        const requests = performance.getEntriesByType('resource').map(r => r.name);
        return {imgs, links, ids, requests, title: document.title};
    """)


def load(driver, url: str) -> dict:
    driver.get_log("browser")  # drop earlier messages
    driver.get(url)
    driver.execute_script("return new Promise(r => document.readyState === 'complete' ? r() : "
                          "window.addEventListener('load', () => r()));")
    time.sleep(0.3)  # let late console messages arrive
    return page_state(driver)


def check_page(driver, url: str, base: str) -> tuple[dict, list[str]]:
    """Load ``url``; return its state and the problems found on it."""
    state = load(driver, url)
    problems = [f"{url}: console {msg}" for msg in console_errors(driver)]
    for img in state["imgs"]:
        if not img["complete"] or img["width"] <= 0:
            problems.append(f"{url}: image does not load: {img['src']}")
    for req in state["requests"]:
        if not (req.startswith(base) or req.startswith("data:")):
            problems.append(f"{url}: network request outside the report: {req}")
    return state, problems


def internal_links(state: dict, base: str) -> list[str]:
    return [link["url"] for link in state["links"]
            if link["url"].startswith(base) or link["raw"].startswith("#")]


def test_report_in_headless_chromium(built_report, browser):
    report = built_report / "report"
    with serve(report) as base:
        index_url = base + "index.html"
        state, problems = check_page(browser, index_url, base)
        images = len(state["imgs"])  # the figures are on the papers' pages, linked from the index

        # Screenshot of the top of the report (test artefact).
        browser.execute_script("window.scrollTo(0, 0)")
        shot = Path(os.environ.get("REPORT_SCREENSHOT") or ROOT / "report" / "screenshot.png")  # git-ignored
        shot.parent.mkdir(parents=True, exist_ok=True)
        assert browser.save_screenshot(str(shot)) and shot.stat().st_size > 10_000
        print(f"screenshot of the report's top: {shot}")

        # Every internal link: the file is served, and its #fragment exists on the target page.
        targets: dict[str, set[str]] = {}
        for url in internal_links(state, base):
            page, _, fragment = url.partition("#")
            # "#explore?verdict=differs&paper=markov": the claims explorer (#explore) with its filters
            targets.setdefault(page, set()).add(fragment.partition("?")[0])
        assert len(targets) > 1, "the report links to no other page"
        own_ids = set(state["ids"])
        for page, fragments in sorted(targets.items()):
            if page == index_url:
                problems += [f"index.html: link to missing anchor #{f}" for f in fragments if f and f not in own_ids]
                continue
            try:
                with urllib.request.urlopen(page, timeout=10) as resp:
                    status = resp.status
            except OSError as exc:
                problems.append(f"broken link {page.removeprefix(base)}: {exc}")
                continue
            if status != 200:
                problems.append(f"broken link {page.removeprefix(base)}: HTTP {status}")
                continue
            if page.endswith(".html"):
                sub_state, sub_problems = check_page(browser, page, base)
                problems += sub_problems
                images += len(sub_state["imgs"])
                ids = set(sub_state["ids"])
                problems += [f"{page.removeprefix(base)}: link to missing anchor #{f}"
                             for f in fragments if f and f not in ids]
        assert not problems, "\n".join(problems)
        assert images, "the report shows no image"

        # The scorecard equals the claims tables (the CSVs and the tables shown on the papers' pages).
        load(browser, index_url)
        score = browser.execute_script("""
            const out = {};
            for (const tr of document.querySelectorAll('#scorecard-table tr[data-paper]')) {
                const row = {};
                for (const td of tr.querySelectorAll('td[class*="n-"]')) {
                    const cls = Array.from(td.classList).find(c => c.startsWith('n-'));
                    row[cls.slice(2)] = parseInt(td.textContent, 10);
                }
                out[tr.dataset.paper] = row;
            }
            return out;
        """)
        tables = {}
        for page in sorted(report.glob("paper-*.html")):
            load(browser, base + page.name)
            tables.update(browser.execute_script("""
            const tables = {};
            for (const t of document.querySelectorAll('table.claims[data-paper]')) {
                tables[t.dataset.paper] = Array.from(t.querySelectorAll('tr.claim')).map(r => r.dataset.verdict);
            }
            return tables;
            """))
    claims = {p.stem: pd.read_csv(p) for p in sorted((built_report / "results" / "claims").glob("*.csv"))}
    assert claims, "no claims table was built"
    assert set(score) == set(claims) | {"total"}
    for slug, frame in claims.items():
        expected = {"claims": len(frame), **{v: int((frame["verdict"] == v).sum()) for v in VERDICTS}}
        assert {k: score[slug][k] for k in expected} == expected, slug
        assert sorted(tables[slug]) == sorted(frame["verdict"].astype(str)), slug
    for key in ("claims", *VERDICTS):
        assert score["total"][key] == sum(score[s][key] for s in claims), key


# ----------------------------------------------------------------------------- provenance panels
def test_every_figure_panel_names_an_existing_rule_and_function(built_report):
    """Each figure's provenance panel names a rule of the workflow and an importable source function."""
    import re

    from netrepro.pipeline.runner import resolve

    rules = set(snakemake(built_report, "--list-rules").stdout.split())
    # every paper's page, where its figures are (report/paper-<slug>.html)
    text = "".join(p.read_text() for p in sorted((built_report / "report").glob("paper-*.html")))
    panels = re.findall(r'<figure id="([^"]+)" data-figure="([^"]+)">.*?<div class="prov" data-rule="([^"]*)" '
                        r'data-source="([^"]*)" data-function="([^"]*)" data-line="([^"]*)"', text, re.S)
    figures = re.findall(r'<figure id="', text)
    assert panels and len(panels) == len(figures), "a figure has no provenance panel"
    for fig_id, fig_path, rule, source, function, line in panels:
        assert rule in rules, f"{fig_id}: rule {rule!r} is not a rule of the workflow"
        func = resolve(function)
        assert callable(func), f"{fig_id}: {function} is not a function"
        assert (built_report / source).is_file(), f"{fig_id}: no file {source}"
        assert source.endswith(func.__module__.replace(".", "/") + ".py"), f"{fig_id}: {function} not in {source}"
        assert re.search(rf"^def {func.__name__}\(", (built_report / source).read_text(), re.M), \
            f"{fig_id}: {source} does not define {func.__name__}"
        assert int(line) > 0
        assert f"--forcerun {rule} {rule}" in text


def test_snakemake_report_view(built_report):
    """Snakemake's own report (the second, standard view) builds with the figures' captions."""
    out = built_report / "report" / "snakemake_report.html"
    snakemake(built_report, "--report", str(out.relative_to(built_report)), "report")
    assert out.stat().st_size > 50_000


def test_snakemakes_report_sealed_by_relocate_runs_in_chromium(built_report, browser):
    """Issue 38: Snakemake's report, sealed by ``relocate`` as ``make report`` does, still runs under its
    content security policy: no console error (a refused script or eval is one), the rule graph is drawn."""
    import subprocess
    import sys

    from selenium.webdriver.common.by import By

    out = built_report / "report" / "snakemake_report.html"
    snakemake(built_report, "--report", str(out.relative_to(built_report)), "report")
    subprocess.run([sys.executable, "-m", "netrepro", "report", "relocate", str(out.relative_to(built_report))],
                   cwd=built_report, check=True)
    assert out.read_text().count('http-equiv="Content-Security-Policy"') == 1
    with serve(out.parent) as base:
        state, problems = check_page(browser, base + out.name, base)
        browser.find_element(By.XPATH, "//span[normalize-space(.)='Workflow']/ancestor::a[1]").click()
        time.sleep(1.5)
        drawn = browser.execute_script("return document.querySelectorAll('#rulegraph svg, #rulegraph canvas').length")
        problems += [f"after opening the rule graph: console {msg}" for msg in console_errors(browser)]
    assert not problems, "\n".join(problems)
    assert state["title"] == "Snakemake Report" and drawn > 0
