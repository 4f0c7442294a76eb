"""The report as a reader navigates it (issue 41 item 1), in a real headless Chromium.

* the claims explorer of ``report/index.html``, opened from ``file://`` (no server, no network):
  filtering it by verdict shows exactly the claims and findings of that verdict in the built
  ``results/claims/*.csv`` and ``results/findings/*.csv``; a count of the scorecard filters it to
  the rows it counts (through the URL fragment ``#explore?...`` that the script reads);
* no page is wider than a 420-px window (the index and a paper's page);
* dark mode (``prefers-color-scheme: dark``, emulated through the DevTools protocol) is a palette of
  its own;
* axe-core (shipped by ``axe-selenium-python``) finds no violation of impact serious or critical on
  the index and on a paper's page.

Uses the session's built copy (``built_repo``; ``NETREPRO_BUILT_REPORT=/path`` reuses one) and the
browser of ``tests/test_report_browser.py``.
"""

from __future__ import annotations

import re
from pathlib import Path

import pandas as pd
import pytest

from .test_report_browser import browser, console_errors, load, serve  # noqa: F401  (fixture)

pytestmark = [pytest.mark.slow, pytest.mark.xdist_group("workflow")]

VISIBLE_ROWS = """
    return Array.from(document.querySelectorAll('#explore-table tbody tr'))
        .filter(r => !r.hidden && r.offsetParent !== null)
        .map(r => [r.dataset.paper, r.dataset.kind, r.dataset.verdict, r.cells[2].textContent.trim()]);
"""


def _expected(report_root: Path, verdict: str) -> list[list[str]]:
    """(paper, kind, verdict, id) of every claim and finding with ``verdict`` in the built tables."""
    rows = []
    for kind, folder, ident in (("claim", "claims", "claim_id"), ("finding", "findings", "finding_id")):
        for path in sorted((report_root / "results" / folder).glob("*.csv")):
            frame = pd.read_csv(path, dtype=str, keep_default_na=False)
            for _, row in frame[frame["verdict"].str.strip() == verdict].iterrows():
                rows.append([path.stem, kind, verdict, row[ident]])
    return sorted(rows)


def _select(driver, key: str, value: str) -> None:
    from selenium.webdriver.support.ui import Select

    Select(driver.find_element("id", f"explore-{key}")).select_by_value(value)


def _click(driver, href: str) -> None:
    """Click the scorecard's count linking to ``href`` (a DOM click: the sticky navigation may cover it)."""
    link = driver.find_element("css selector", f'#scorecard-table a.count[href="{href}"]')
    driver.execute_script("arguments[0].click()", link)


@pytest.fixture(scope="module")
def index_url(built_repo):
    return (built_repo / "report" / "index.html").as_uri()


def test_the_explorer_filters_by_verdict_from_file_url(built_repo, browser, index_url):  # noqa: F811
    load(browser, index_url)
    assert browser.execute_script("return !document.getElementById('explore-controls').hidden"), \
        "the explorer's script did not run (its hash is not in the page's policy?)"
    total = browser.execute_script("return document.querySelectorAll('#explore-table tbody tr').length")
    assert len(browser.execute_script(VISIBLE_ROWS)) == total  # nothing hidden before a filter
    claims = sum(len(pd.read_csv(p)) for p in (built_repo / "results" / "claims").glob("*.csv"))
    findings = sum(len(pd.read_csv(p)) for p in (built_repo / "results" / "findings").glob("*.csv"))
    errata = sum(len(pd.read_csv(p)) for p in (built_repo / "results" / "errata").glob("*.csv"))
    assert total == claims + findings + errata
    found = {v for _, _, v, _ in browser.execute_script(VISIBLE_ROWS) if v}
    common = max(found, key=lambda v: len(_expected(built_repo, v)))
    for verdict in dict.fromkeys(["differs", common]):
        _select(browser, "verdict", verdict)
        shown = sorted(browser.execute_script(VISIBLE_ROWS))
        assert shown == _expected(built_repo, verdict), verdict
        assert browser.find_element("id", "explore-count").text.startswith(f"{len(shown)} of {total}")
        assert f"verdict={verdict}" in browser.execute_script("return location.hash")
    # the text filter narrows within the verdict; "show all" brings every row back
    text = browser.find_element("id", "explore-text")
    text.send_keys("zz-no-such-word-zz")
    assert browser.execute_script(VISIBLE_ROWS) == []
    browser.find_element("id", "explore-reset").click()
    assert len(browser.execute_script(VISIBLE_ROWS)) == total
    assert not console_errors(browser)


def test_a_scorecard_count_filters_the_explorer(built_repo, browser, index_url):  # noqa: F811
    load(browser, index_url)
    links = browser.execute_script("""
        return Array.from(document.querySelectorAll('#scorecard-table tr[data-paper] a.count')).map(a => ({
            href: a.getAttribute('href'), n: parseInt(a.textContent, 10),
            paper: a.closest('tr').dataset.paper, cls: a.closest('td').className}));
    """)
    verdict_links = [link for link in links if "verdict=" in link["href"] and link["paper"] != "total"]
    assert verdict_links, "no count of the scorecard links to the explorer"
    link = next((x for x in verdict_links if "verdict=differs" in x["href"]), verdict_links[0])
    verdict = re.search(r"verdict=([\w]+)", link["href"]).group(1)
    _click(browser, link["href"])
    shown = browser.execute_script(VISIBLE_ROWS)
    assert len(shown) == link["n"] > 0
    assert {(p, k, v) for p, k, v, _ in shown} == {(link["paper"], "claim", verdict)}
    assert browser.execute_script("return document.getElementById('explore-verdict').value") == verdict
    # the same fragment opened directly (a link from elsewhere) filters on load
    load(browser, index_url + link["href"])
    assert len(browser.execute_script(VISIBLE_ROWS)) == link["n"]
    # a total count filters every paper
    total = next(x for x in links if x["paper"] == "total" and f"verdict={verdict}" in x["href"])
    _click(browser, total["href"])
    assert len(browser.execute_script(VISIBLE_ROWS)) == total["n"]
    assert not console_errors(browser)


def test_no_page_is_wider_than_a_phone(built_repo, browser):  # noqa: F811
    report = built_repo / "report"
    pages = ["index.html", next(p.name for p in sorted(report.glob("paper-*.html")))]
    browser.execute_cdp_cmd("Emulation.setDeviceMetricsOverride",
                            {"width": 420, "height": 900, "deviceScaleFactor": 1, "mobile": False})
    try:
        for name in pages:
            load(browser, (report / name).as_uri())
            width = browser.execute_script("return document.documentElement.scrollWidth")
            wide = browser.execute_script("""
                return Array.from(document.querySelectorAll('body *'))
                    .filter(e => e.getBoundingClientRect().right > 421 && !e.closest('.scroll, .prov'))
                    .slice(0, 5).map(e => e.tagName + '.' + e.className + '#' + e.id);
            """)
            assert width <= 420, f"{name}: {width} px wide at a 420-px window; widest: {wide}"
    finally:
        browser.execute_cdp_cmd("Emulation.clearDeviceMetricsOverride", {})


def test_dark_mode_has_its_own_palette(built_repo, browser):  # noqa: F811
    url = (built_repo / "report" / "index.html").as_uri()
    style = "return [getComputedStyle(document.body).backgroundColor, getComputedStyle(document.body).color]"
    try:
        colours = {}
        for scheme in ("light", "dark"):
            browser.execute_cdp_cmd("Emulation.setEmulatedMedia",
                                    {"features": [{"name": "prefers-color-scheme", "value": scheme}]})
            load(browser, url)
            colours[scheme] = browser.execute_script(style)
    finally:
        browser.execute_cdp_cmd("Emulation.setEmulatedMedia", {"features": []})
    assert colours["dark"][0] != colours["light"][0] and colours["dark"][1] != colours["light"][1], colours


def test_no_serious_accessibility_violation(built_repo, browser):  # noqa: F811
    axe_selenium_python = pytest.importorskip("axe_selenium_python",
                                              reason="axe-selenium-python not installed (pip install -e '.[test]')")
    report = built_repo / "report"
    pages = ["index.html", next(p.name for p in sorted(report.glob("paper-*.html")))]
    problems = []
    # axe-core is injected as a script, and axe compiles functions from strings: the pages' content
    # security policy forbids both. The policy is bypassed through the DevTools protocol for the
    # scan only (Page.setBypassCSP, before the page loads); the pages themselves stay sealed.
    browser.execute_cdp_cmd("Page.enable", {})
    browser.execute_cdp_cmd("Page.setBypassCSP", {"enabled": True})
    browser.set_script_timeout(120)
    try:
        with serve(report) as base:
            for scheme in ("light", "dark"):  # the dark palette's contrasts too
                browser.execute_cdp_cmd("Emulation.setEmulatedMedia",
                                        {"features": [{"name": "prefers-color-scheme", "value": scheme}]})
                for name in pages:
                    load(browser, base + name)
                    axe = axe_selenium_python.Axe(browser)
                    axe.inject()
                    results = axe.run()
                    for v in results["violations"]:
                        if v["impact"] in ("serious", "critical"):
                            targets = [n["target"] for n in v["nodes"][:3]]
                            problems.append(f"{name} ({scheme}): {v['id']} ({v['impact']}, {len(v['nodes'])} "
                                            f"nodes): {v['help']} {targets}")
    finally:
        browser.execute_cdp_cmd("Emulation.setEmulatedMedia", {"features": []})
        browser.execute_cdp_cmd("Page.setBypassCSP", {"enabled": False})
    assert not problems, "\n".join(problems)
