"""A paper's notebook that fails or hangs stops its rule with the notebook's error (papermill's
execution timeout): the build never hangs on a notebook."""

import os
import subprocess
import sys
import tempfile
import time

import nbformat
import nbformat.v4 as nbf
import pytest

from netrepro.report.notebooks import NotebookError, execute_notebook, make_notebook


def _notebook(path, source):
    nb = nbf.new_notebook(cells=[nbf.new_code_cell('slug = "x"\nroot = "."', metadata={"tags": ["parameters"]}),
                                 nbf.new_code_cell(source)])
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nbformat.write(nb, str(path))
    return path


def test_a_notebook_that_sleeps_is_stopped_by_the_timeout(tmp_path):
    notebook = _notebook(tmp_path / "sleeps.ipynb", "import time\ntime.sleep(120)")
    # the subprocess timeout (100 s, below the cell's 120 s sleep) fails the test if the notebook is waited out
    proc = subprocess.run([sys.executable, "-m", "netrepro", "report", "notebook", "--slug", "x", "--notebook",
                           str(notebook), "--html", str(tmp_path / "x.html"), "--timeout", "1"],
                          cwd=tmp_path, capture_output=True, text=True, timeout=100)
    assert proc.returncode == 1
    assert "ran longer than the execution timeout of 1 s" in proc.stderr
    assert not (tmp_path / "x.html").exists()


def test_a_failing_cell_names_the_notebook_and_the_error(tmp_path):
    notebook = _notebook(tmp_path / "fails.ipynb", 'raise ValueError("table results/x.csv has no column p")')
    with pytest.raises(NotebookError, match=r"fails\.ipynb \(paper x\): cell \d+ failed: ValueError: table "
                                            r"results/x\.csv has no column p"):
        execute_notebook("x", notebook, tmp_path / "x.html", root=tmp_path, timeout=60)
    assert not (tmp_path / "x.html").exists()


def test_the_default_notebook_imports_the_report_helpers(tmp_path):
    path = make_notebook("p", tmp_path / "p.ipynb")
    sources = [c.source for c in nbformat.read(str(path), as_version=4).cells]
    assert sources[0] == 'slug = "p"\nroot = "."'
    assert "from netrepro.report.notebooks import figure_captions, show_figures, show_table" in sources[1]


def test_the_kernel_talks_over_private_unix_sockets_and_is_shut_down(tmp_path):
    # TCP ports are picked by binding port 0 and releasing it, so two kernels started at once by
    # different processes can take the same port and one dies ("Address already in use", seen in
    # CI). The kernel must use IPC sockets in a folder of its own, removed afterwards.
    notebook = _notebook(tmp_path / "transport.ipynb",
                         "import os\nfrom ipykernel.kernelapp import IPKernelApp\n"
                         "app = IPKernelApp.instance()\nprint(app.transport, app.ip, os.getpid())")
    execute_notebook("x", notebook, tmp_path / "x.html", root=tmp_path, timeout=60)
    printed = nbformat.read(str(tmp_path / "x.ipynb"), as_version=4).cells[-1].outputs[0]["text"].split()
    transport, ip, pid = printed[0], printed[1], int(printed[2])
    assert transport == "ipc"
    assert "netrepro-kernel-" in ip and not os.path.exists(os.path.dirname(ip))
    deadline = time.monotonic() + 10
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not _alive(pid)  # shut down by nbclient, not left to notice its parent's exit


def _alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_the_kernel_sockets_move_to_tmp_when_tmpdir_is_too_long(tmp_path):
    from netrepro.report.notebooks import SOCKET_PATH_MAX, _socket_parent

    with tempfile.TemporaryDirectory(dir="/tmp") as short:  # tmp_path itself may be long under xdist
        assert _socket_parent(short) == short
    deep = tmp_path / ("d" * 60) / ("e" * 60)
    deep.mkdir(parents=True)
    assert len(str(deep)) > SOCKET_PATH_MAX
    assert _socket_parent(str(deep)) == "/tmp"  # Linux and macOS both have /tmp
    # the bound itself: the longest socket is <parent>/netrepro-kernel-XXXXXXXX/kernel-NN
    socket_tail = len("/netrepro-kernel-12345678/kernel-99")
    with tempfile.TemporaryDirectory(dir="/tmp") as base:
        fits = os.path.join(base, "p" * (SOCKET_PATH_MAX - socket_tail - len(base) - 1))
        over = fits + "p"
        os.makedirs(fits)
        os.makedirs(over)
        assert len(fits) + socket_tail == SOCKET_PATH_MAX
        assert _socket_parent(fits) == fits
        assert _socket_parent(over) == "/tmp"


# a 1x1 PNG
_PIXEL = bytes.fromhex("89504e470d0a1a0a0000000d4948445200000001000000010806000000" "1f15c4890000000d49444154789c6360000002000154a24f5d0000000049454e44ae426082")


def test_a_hostile_caption_is_inert_text_in_the_notebook_page(tmp_path):
    """Issue 38: a caption's raw-HTML script, file inclusion and javascript: link, in the notebook page."""
    from html.parser import HTMLParser

    from netrepro.report.captions import link_allowed

    from .test_captions import HOSTILE_CAPTION

    (tmp_path / "workflow" / "report" / "x").mkdir(parents=True)
    (tmp_path / "workflow" / "report" / "x" / "fig1.rst").write_text(HOSTILE_CAPTION)
    (tmp_path / "figures" / "x").mkdir(parents=True)
    (tmp_path / "figures" / "x" / "fig1.png").write_bytes(_PIXEL)
    notebook = make_notebook("x", tmp_path / "x.ipynb")
    page = execute_notebook("x", notebook, tmp_path / "x.html", root=tmp_path, timeout=60).read_text()

    class Live(HTMLParser):
        def __init__(self):
            super().__init__()
            self.scripts, self.hrefs, self.handlers, self.csp, self.text = [], [], [], [], []

        def handle_starttag(self, tag, attrs):
            attrs = dict(attrs)
            if tag == "script" and attrs.get("type", "text/javascript") in ("text/javascript", "module"):
                self.scripts.append(attrs)  # a script a browser would run (nbconvert's MathJax config is not one)
            if tag == "a" and attrs.get("href") is not None:
                self.hrefs.append(attrs["href"])
            if tag == "meta" and attrs.get("http-equiv", "").lower() == "content-security-policy":
                self.csp.append(attrs["content"])
            self.handlers += [k for k in attrs if k.startswith("on")]

        def handle_data(self, data):
            self.text.append(data)

    live = Live()
    live.feed(page)
    assert live.scripts == [] and live.handlers == []
    assert [h for h in live.hrefs if not link_allowed(h)] == []
    text = "".join(live.text)  # what the reader sees: the hostile parts as text
    assert '<script>document.title = "PWNED"</script>' in text
    assert ".. include:: /etc/passwd" in text and "root:x:0:0" not in page
    assert "link <javascript:alert(document.domain)>" in text
    assert len(live.csp) == 1 and "script-src 'none'" in live.csp[0] and "default-src 'none'" in live.csp[0]
    assert page.index("Content-Security-Policy") < page.index("<script")  # the policy governs every script
