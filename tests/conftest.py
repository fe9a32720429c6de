"""Suite-wide reporting: say plainly when the browser tests did not run."""

from __future__ import annotations


def pytest_terminal_summary(terminalreporter, exitstatus, config):
    skipped = [r for r in terminalreporter.stats.get("skipped", []) if "test_viewer_browser" in str(getattr(r, "nodeid", ""))]
    if skipped:
        reason = skipped[0].longrepr[2] if isinstance(skipped[0].longrepr, tuple) else str(skipped[0].longrepr)
        terminalreporter.write_sep("=", "BROWSER TESTS SKIPPED", yellow=True, bold=True)
        terminalreporter.write_line(f"{len(skipped)} viewer tests in a real browser did not run: {reason}")
        terminalreporter.write_line("install Debian's chromium (apt-get install chromium) to run them; .ci/run does")
