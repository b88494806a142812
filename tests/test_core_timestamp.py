"""The time files are stamped with: SOURCE_DATE_EPOCH when set (reproducible-builds.org), else now, in UTC."""

from __future__ import annotations

import uuid
from datetime import datetime, timezone

import pytest

from tabletcad.cli import main
from tabletcad.errors import DesignError
from tabletcad.io.timestamp import content_uuid, stamp_time, zip_date_time


def test_source_date_epoch_is_the_stamp(monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    t = stamp_time()
    assert t == datetime(2023, 11, 14, 22, 13, 20, tzinfo=timezone.utc)
    assert t.isoformat() == "2023-11-14T22:13:20+00:00"
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "0")
    assert stamp_time().isoformat() == "1970-01-01T00:00:00+00:00"


def test_without_source_date_epoch_the_stamp_is_now_in_utc(monkeypatch):
    monkeypatch.delenv("SOURCE_DATE_EPOCH", raising=False)
    before = datetime.now(timezone.utc).replace(microsecond=0)
    t = stamp_time()
    assert t.tzinfo is timezone.utc and t.microsecond == 0
    assert before <= t <= datetime.now(timezone.utc)


@pytest.mark.parametrize("raw", ["abc", "-5", "1.5", "", "1e9", "253402300800", "٣"])
def test_a_malformed_source_date_epoch_is_refused(monkeypatch, raw):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", raw)
    with pytest.raises(DesignError) as e:
        stamp_time()
    assert str(e.value) == (f"SOURCE_DATE_EPOCH = {raw!r} is not allowed: must be a whole number of seconds since "
                            "1970-01-01 00:00 UTC, 0 to 253402300799 (reproducible-builds.org)")


def test_the_command_line_refuses_a_malformed_source_date_epoch_in_one_line(monkeypatch, capsys, tmp_path):
    # matplotlib reads the variable too: a picture saved as SVG or PDF had raised a bare ValueError (exit 1)
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "yesterday")
    rc = main(["shapes"])
    out, err = capsys.readouterr()
    assert rc == 2 and out == ""
    assert err.splitlines() == ["error: SOURCE_DATE_EPOCH = 'yesterday' is not allowed: must be a whole number of "
                                "seconds since 1970-01-01 00:00 UTC, 0 to 253402300799 (reproducible-builds.org)"]


def test_content_uuid_is_a_function_of_its_parts():
    a = content_uuid("tabletcad DXF fingerprint", "text")
    assert a == content_uuid("tabletcad DXF fingerprint", b"text")
    assert a != content_uuid("tabletcad DXF version", "text")
    assert a != content_uuid("tabletcad DXF fingerprint", "text ")
    assert content_uuid("ab", "c") != content_uuid("a", "bc")  # parts are delimited
    assert isinstance(a, uuid.UUID) and a.version == 5


def test_zip_dates_are_clamped_to_the_format():
    assert zip_date_time(datetime(2023, 11, 14, 22, 13, 20, tzinfo=timezone.utc)) == (2023, 11, 14, 22, 13, 20)
    assert zip_date_time(datetime(1970, 1, 1, tzinfo=timezone.utc)) == (1980, 1, 1, 0, 0, 0)
    assert zip_date_time(datetime(9999, 1, 1, tzinfo=timezone.utc)) == (2107, 12, 31, 23, 59, 58)
