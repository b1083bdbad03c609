"""The export: the comfort check as yes/no, and BIDS behavioural files that read back."""

from __future__ import annotations

import csv
from pathlib import Path

from study_helpers import pilot_study

from feelmysign.study.export import export_study


def test_the_comfort_check_is_exported_as_yes_and_no(tmp_path: Path) -> None:
    store = pilot_study(tmp_path)
    first, second = store.add_participant(), store.add_participant()
    for code in (first, second):
        store.set_consent(code, True)
    store.record_comfort(first, [True, False], adjusted=True)
    store.record_comfort(second, [True, True], adjusted=False)
    export_study(store, tmp_path / "out")
    with (tmp_path / "out" / "comfort.csv").open() as file:
        rows = [
            (r["participant"], r["item"], r["question"], r["answer"], r["adjusted"])
            for r in csv.DictReader(file)
        ]
    assert rows == [
        ("P01", "1", "Does the sleeve sit comfortably?", "yes", "yes"),
        ("P01", "2", "Can you feel every motor?", "no", "yes"),
        ("P02", "1", "Does the sleeve sit comfortably?", "yes", "no"),
        ("P02", "2", "Can you feel every motor?", "yes", "no"),
    ]
