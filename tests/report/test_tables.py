"""softdesign.report.tables without a build: the rows the page's tables are made of."""

from __future__ import annotations

from softdesign.pipeline.versions import software_versions
from softdesign.report.tables import REPORT_PACKAGES, software_rows


def test_software_rows_show_what_the_build_recorded_beside_what_draws_the_page():
    now = software_versions(REPORT_PACKAGES)
    rows = software_rows({"software": {"softdesign": "0.0.1", "numpy": "1.26.0"}})
    assert rows[:2] == [("softdesign", "0.0.1", now["softdesign"]), ("numpy", "1.26.0", now["numpy"])]
    assert rows[2:] == [(name, "-", version) for name, version in now.items() if name not in ("softdesign", "numpy")]
