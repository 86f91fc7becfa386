"""report.html in a real headless browser (Debian's chromium, installed by
tools/setup.sh): it renders, every image loads, and the page logs nothing to
the console. A copy of the report with a small checking script appended is
what the browser opens; the shipped report carries no script."""
import re
import shutil
import subprocess

import pytest

from pyins import report, run_scenario, scenario

CHECK = """
<script>
window.addEventListener("load", function () {
  var imgs = Array.prototype.slice.call(document.images);
  var ok = imgs.filter(function (i) { return i.complete && i.naturalWidth > 0; }).length;
  document.body.setAttribute("data-images", ok + "/" + imgs.length);
});
</script>
</body>"""


def _browser():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        path = shutil.which(name)
        if path:
            return path
    pytest.fail("no chromium: tools/setup.sh installs Debian's chromium for this test")


def test_report_renders_in_headless_chromium(tmp_path):
    browser = _browser()
    scn = scenario.load("seed003").with_overrides({"duration": "0.2 h"})
    out = tmp_path / "run"
    run_scenario.execute(scn, str(out))
    page = report.render(str(out))
    text = open(page).read()
    assert "<script" not in text
    n_img = len(re.findall(r"<img ", text))
    assert n_img >= 3                         # errors, turntable, scheme comparison
    check = out / "report_check.html"
    check.write_text(text.replace("</body>", CHECK))
    proc = subprocess.run([browser, "--headless=new", "--no-sandbox", "--disable-gpu",
                           "--enable-logging=stderr", "--v=0", "--virtual-time-budget=5000",
                           "--dump-dom", check.as_uri()], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    dom = proc.stdout
    assert "Seed 003" in dom and "Beside the paper" in dom
    assert f'data-images="{n_img}/{n_img}"' in dom, re.findall(r'data-images="[^"]*"', dom)
    console = [ln for ln in proc.stderr.splitlines() if ":CONSOLE" in ln]
    assert console == [], console
