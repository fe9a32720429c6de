"""Results files read as untrusted input (file-safety review F3, F9-F11): a file must be complete
and every signal must match its checksum; links, external storage, virtual and compressed
datasets, and shapes larger than the file are refused before any data is read; every problem is
one `error:` line from the command line, never a traceback."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import mechsys as ms
from mechsys.errors import ResultsError

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    m = ms.Model("p", gravity=(0, -9.81, 0))
    b = m.add_body("rod", 1.0, ms.inertia.rod(1.0, 1.0), com=(0.5, 0, 0))
    m.add_joint(ms.joints.Revolute("hinge", m.ground, b, q0=0.5))
    res = ms.simulate(m, 0.2, ms.RK4(dt=1e-3), output_dt=1e-2)
    path = tmp_path_factory.mktemp("res") / "good.h5"
    res.save(path)
    return path


def copy(saved: Path, tmp_path: Path, name="x.h5") -> Path:
    out = tmp_path / name
    out.write_bytes(saved.read_bytes())
    return out


def refused(path: Path, fragment: str) -> None:
    with pytest.raises(ResultsError, match=fragment):
        ms.Results.load(path)
    p = subprocess.run([sys.executable, "-m", "mechsys", "signals", str(path)], capture_output=True, text=True, cwd=ROOT)
    assert p.returncode != 0, p.stdout
    assert p.stderr.startswith("error: ") and "Traceback" not in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1, p.stderr


def test_a_good_file_loads_with_its_checksums(saved):
    res = ms.Results.load(saved)
    assert res["joint/hinge/q"].shape == (21,)
    with h5py.File(saved) as f:
        assert f.attrs["complete"] and f.attrs["format_version"] == 2
        assert f.attrs["signal_count"] == len(res.names())
        assert all("crc32" in f[n].attrs for n in res.names())


def test_a_file_without_its_completeness_marker_is_refused(saved, tmp_path):
    p = copy(saved, tmp_path)
    with h5py.File(p, "a") as f:
        del f.attrs["complete"]
    refused(p, "incomplete results file")


def test_a_flipped_byte_in_a_signal_is_found_naming_the_signal(saved, tmp_path):
    p = copy(saved, tmp_path)
    with h5py.File(p) as f:
        offset = f["joint/hinge/q"].id.get_offset()
    data = bytearray(p.read_bytes())
    data[offset + 8 * 5 + 3] ^= 0x10
    p.write_bytes(bytes(data))
    refused(p, r"signal 'joint/hinge/q' is corrupt \(checksum mismatch\)")


def test_links_external_storage_and_virtual_datasets_are_refused(saved, tmp_path):
    secret = tmp_path / "secret.txt"
    secret.write_bytes(b"precious private bytes!!" * 4)
    # external storage pointing at another local file
    p = copy(saved, tmp_path, "ext.h5")
    with h5py.File(p, "a") as f:
        f.create_dataset("body/leak", shape=(12,), dtype="f8", external=[(str(secret), 0, 96)])
    refused(p, "signal 'body/leak' keeps its data in other files")
    # an external link and a soft link
    p = copy(saved, tmp_path, "link.h5")
    with h5py.File(p, "a") as f:
        f["body/elsewhere"] = h5py.ExternalLink(str(saved), "/t")
    refused(p, "signal 'body/elsewhere' is a external link")
    p = copy(saved, tmp_path, "soft.h5")
    with h5py.File(p, "a") as f:
        f["again"] = h5py.SoftLink("/t")
    refused(p, "signal 'again' is a soft link")
    # a virtual dataset
    p = copy(saved, tmp_path, "virtual.h5")
    layout = h5py.VirtualLayout(shape=(21,), dtype="f8")
    layout[:] = h5py.VirtualSource(str(saved), "t", shape=(21,))
    with h5py.File(p, "a") as f:
        f.create_virtual_dataset("virt", layout)
    refused(p, "signal 'virt' keeps its data in other files")


def test_a_small_file_declaring_a_huge_signal_is_refused_before_reading(saved, tmp_path):
    p = copy(saved, tmp_path, "bomb.h5")
    with h5py.File(p, "a") as f:
        # 16 GiB of zeros, a few kB on disk once compressed
        f.create_dataset("bomb", shape=(1 << 31,), dtype="f8", chunks=(1 << 20,), compression="gzip", fillvalue=0.0)
    assert p.stat().st_size < 1 << 20
    refused(p, "signal 'bomb' is compressed or filtered")
    p = copy(saved, tmp_path, "big.h5")
    with h5py.File(p, "a") as f:
        f.create_dataset("big", shape=(1 << 31,), dtype="f8")  # never written: no space taken
    refused(p, "signal 'big' declares 17179869184 bytes, more than the file holds")


def test_damaged_attributes_and_foreign_types_give_one_error_line(saved, tmp_path):
    p = copy(saved, tmp_path, "attr.h5")
    with h5py.File(p, "a") as f:
        f.attrs["signal_order"] = "{not json"
    refused(p, "unreadable attribute 'signal_order'")
    p = copy(saved, tmp_path, "model.h5")
    with h5py.File(p, "a") as f:
        f.attrs["model"] = "{not json"
    res = ms.Results.load(p)
    with pytest.raises(ResultsError, match="results attribute 'model' is not readable JSON"):
        res.model
    p = copy(saved, tmp_path, "strings.h5")
    with h5py.File(p, "a") as f:
        f.create_dataset("names", data=np.array([b"a", b"b"]))
    refused(p, "signal 'names' has type")
    p = copy(saved, tmp_path, "future.h5")
    with h5py.File(p, "a") as f:
        f.attrs["format_version"] = 99
    refused(p, "results format version 99")


def test_a_format_1_file_still_loads_with_a_warning(saved, tmp_path):
    p = copy(saved, tmp_path, "old.h5")
    with h5py.File(p, "a") as f:
        f.attrs["format_version"] = 1
        del f.attrs["complete"]
        for n in ("t", "joint/hinge/q"):
            del f[n].attrs["crc32"]
    with pytest.warns(UserWarning, match="format 1"):
        res = ms.Results.load(p)
    assert np.allclose(res["joint/hinge/q"][0], 0.5)


@pytest.mark.parametrize("change, fragment", [
    (lambda f: f.__delitem__("t"), "no sample times"),
    (lambda f: (f.__delitem__("t"), f.create_dataset("t", data=np.zeros(()))), "signal 't' must be 1-D"),
    (lambda f: (f.__delitem__("t"), f.create_dataset("t", data=np.full(21, np.nan))), "signal 't' must be 1-D, finite"),
    (lambda f: (f.__delitem__("t"), f.create_dataset("t", data=np.arange(21.0)[::-1])), "non-decreasing"),
    (lambda f: f.create_dataset("energy/odd", data=np.zeros(5)), "signal 'energy/odd' has shape (5,)"),
])
def test_results_without_the_schema_of_samples_are_refused(saved, tmp_path, change, fragment):
    """Review F11: each of these gave a Python traceback (or a plot of garbage) from plot/signals."""
    p = copy(saved, tmp_path, "schema.h5")
    with h5py.File(p, "a") as f:
        del f.attrs["complete"]  # edited by hand: claim format 1 so that checksums do not catch it first
        f.attrs["format_version"] = 1
        change(f)
    with pytest.raises(ResultsError, match=re.escape(fragment)):
        ms.Results.load(p)
    proc = subprocess.run([sys.executable, "-m", "mechsys", "plot", str(p), "joint/hinge/q", "-o", str(tmp_path / "o.png")],
                          capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode != 0 and "Traceback" not in proc.stderr and proc.stderr.count("error:") == 1, proc.stderr
