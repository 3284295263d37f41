"""Metadata mutations over every output of ``convert`` and a recording's side files:
each must be a ParseError, or an error (or warning) naming the file; none is
silently accepted.

Every field of the metadata (and every line of ``.gaps``/``.times``) is given
each of :data:`MUTANTS` (wrong JSON types, null, negative, fractional, huge
numbers, extra nesting), is removed, and the text is cut at several places. The
few mutations that are accepted are listed in :data:`HARMLESS` with the reason;
the test fails on any other that reads.
"""

from __future__ import annotations

import copy
import fnmatch
import json
import warnings
from pathlib import Path

import imunoise
import numpy as np
import pytest
from helpers.data import DATA
from imunoise import scale
from imunoise.readers.columnar import META_KEY

SRC = DATA.parent.parent / "python" / "imunoise" / "data" / "vn100_stationary_5min.txt"

#: Wrong values a field is given.
MUTANTS = {
    "true": True,
    "null": None,
    "text": "x",
    "list": [],
    "object": {},
    "negative": -1,
    "fraction": 0.5,
    "huge": 1e308,
    "bigint": 10**40,
    "nested": [[[[1]]]],
    "deep": json.loads("[" * 40 + "]" * 40),
}

#: (field pattern, mutant) pairs that read, and why that is right. A mutant is a
#: key of MUTANTS, or "missing"; patterns as fnmatch.
HARMLESS = {
    # a text the schema takes: the metadata names its source and format; another
    # name is an edit, not a contradiction of the data
    ("source", "text"): "any text names the source",
    ("format", "text"): "any text names the format",
    ("table", "text"): "any text names the message type",
    ("table", "null"): "null: the log came from one table (what read writes)",
    # a rate the schema takes: another valid rate is the metadata's to state
    ("fs", "fraction"): "0.5 Hz is a valid rate",
    # message counts are informational (no analysis uses them); {} is what a log
    # without message types (a CSV) writes, and a type's key may be any name
    ("messages", "object"): "no message types",
    ("messages.*", "missing"): "one message type fewer",
    # kinds added after the first version of the metadata: their absence is how a
    # file written before them says zero (the kinds every version wrote must be there)
    ("issues.counts.time_outlier", "missing"): "older file: zero",
    ("issues.counts.time_reset", "missing"): "older file: zero",
    # the first locations are examples of where issues were, for the summary;
    # none (an empty list or map) is what a log without issues writes
    ("issues.first", "object"): "no example locations",
    ("issues.first.*", "list"): "no example locations of that kind",
    ("issues.first.*", "missing"): "no example locations of that kind",
}


def _harmless(field: str, mutant: str, table: dict) -> bool:
    return any(fnmatch.fnmatchcase(field, pattern) and mutant == m for pattern, m in table)


#: Harmless in a recording's metadata: every field is optional (the recorder
#: writes it at the start and again, with more fields, at the end; older ones
#: wrote fewer), only ``fs`` changes what is read (a missing or null ``fs`` gives
#: the reader's "assuming 40 Hz" warning, which names the log), and the sensor's
#: identity and register fields are whatever texts the sensor answered.
RECORDING_HARMLESS = {
    ("fs", "fraction"): "0.5 Hz is a valid rate",
    ("port", "text"): "any port name",
    ("port", "null"): "not known",
    ("ascii", "text"): "any message name",
    ("ascii", "null"): "ASCII output off",
    ("started", "fraction"): "any time >= 0",
    ("seconds", "fraction"): "any duration >= 0",
    ("identity", "object"): "the sensor answered nothing",
    ("identity.*", "text"): "any text the sensor answered",
    ("identity.*", "missing"): "a register not read",
    ("previous", "object"): "no registers read",
    ("written", "object"): "no registers written",
    ("previous.*", "list"): "a register without fields",
    ("written.*", "list"): "a register without fields",
    ("previous.*", "missing"): "a register not read",
    ("written.*", "missing"): "a register not written",
    ("previous.*[[]0]", "text"): "any field text",
    ("written.*[[]0]", "text"): "any field text",
    ("outages", "list"): "a list of outages (a newer recorder) or a count",
    ("restored", "*"): "not read: what the recorder did at the end",
    ("*", "missing"): "every top-level field is optional (fs: the reader warns)",
}


def _paths(value, prefix=""):
    """Dotted paths of every field (list items by index) of a JSON value."""
    if isinstance(value, dict):
        for k, v in value.items():
            path = f"{prefix}.{k}" if prefix else k
            yield path, (k,)
            for sub, keys in _paths(v, path):
                yield sub, (k, *keys)
    elif isinstance(value, list) and value:
        yield f"{prefix}[0]", (0,)
        for sub, keys in _paths(value[0], f"{prefix}[0]"):
            yield sub, (0, *keys)


def _mutations(meta: dict):
    """(name, field, mutant, mutated text) of every mutation of ``meta``."""
    for field, keys in list(_paths(meta)):
        *parents, last = keys
        for mutant, value in [*MUTANTS.items(), ("missing", None)]:
            m = copy.deepcopy(meta)
            target = m
            for k in parents:
                target = target[k]
            if mutant == "missing":
                if isinstance(target, list):
                    continue  # an item of a list is not a field
                del target[last]
            else:
                target[last] = copy.deepcopy(value)
            yield f"{field}={mutant}", field, mutant, json.dumps(m)
    text = json.dumps(meta)
    for cut in np.linspace(1, len(text) - 1, 8).astype(int):
        yield f"cut at {cut}", "", "cut", text[:cut]


def _outcome(read, names):
    """None when ``read()`` refuses naming one of ``names``; else what happened."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", UserWarning)
        try:
            read()
        except (ValueError, UserWarning) as exc:
            return None if any(n in str(exc) for n in names) else f"unnamed {exc!r}"
        except Exception as exc:  # noqa: BLE001 - any other type is the finding
            return f"{type(exc).__name__}: {exc}"
    return "accepted"


@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    """Every output kind of one damaged log (it has gaps, issues and locations)."""
    from imunoise.cli import main

    tmp = tmp_path_factory.mktemp("mutations")
    raw = SRC.read_bytes().splitlines(keepends=True)
    src = tmp / "d.txt"
    src.write_bytes(b"".join(raw[:100] + [b"$VNYMR,garbage*00\r\n"] + raw[101:300]))
    made = {}
    for suffix in (".npy", ".csv", ".npz", ".parquet", ""):
        out = tmp / f"o{suffix}"
        assert main(["convert", str(src), "-o", str(out), "--fs", "40", "--no-progress"]) == 0
        made[suffix or "dir"] = out
    return made


def _meta_of(kind: str, out: Path) -> tuple[dict, Path | None]:
    if kind in (".npy", ".csv"):
        side = out.with_name(out.name + ".meta.json")
        return json.loads(side.read_text()), side
    if kind == "dir":
        return json.loads((out / "meta.json").read_text()), out / "meta.json"
    if kind == ".npz":
        with np.load(out) as z:
            return json.loads(str(z[META_KEY])), None
    import pyarrow.parquet as pq

    return json.loads(pq.read_metadata(out).metadata[META_KEY.encode()]), None


def _writer(kind: str, out: Path, tmp: Path):
    """A function writing mutated metadata text into a copy of ``out``; returns the
    path to read and the names an error may give."""
    if kind in (".npy", ".csv", "dir"):
        import shutil

        copy_ = tmp / out.name
        (shutil.copytree if kind == "dir" else shutil.copy2)(out, copy_)
        if kind != "dir":
            shutil.copy2(out.with_name(out.name + ".meta.json"), tmp)
        side = copy_ / "meta.json" if kind == "dir" else copy_.with_name(copy_.name + ".meta.json")

        def write(text):
            side.write_text(text)
        return write, copy_, [str(side), str(copy_)]
    if kind == ".npz":
        with np.load(out) as z:
            table = {k: z[k] for k in z.files}
        target = tmp / "m.npz"

        def write(text):
            np.savez(target, **{**table, META_KEY: np.array(text)})
        return write, target, [str(target)]
    import pyarrow.parquet as pq

    table = pq.read_table(out)
    target = tmp / "m.parquet"

    def write(text):
        pq.write_table(table.replace_schema_metadata({META_KEY: text}), target)
    return write, target, [str(target)]


@pytest.mark.parametrize("kind", [".npy", ".csv", ".npz", ".parquet", "dir"])
def test_every_mutation_of_convert_metadata_is_refused(kind, outputs, tmp_path):
    if kind == ".parquet":
        pytest.importorskip("pyarrow")
    out = outputs[kind]
    meta, _ = _meta_of(kind, out)
    assert meta["gaps"]["index"] and meta["issues"]["first"]  # every field has content
    write, target, names = _writer(kind, out, tmp_path)
    tried, accepted, failures = 0, [], []
    for name, field, mutant, text in _mutations(meta):
        write(text)
        # scale.load and imunoise.read, in turn, where both read the output
        reader = scale.load if kind in ("dir", ".npy") and tried % 2 else imunoise.read
        found = _outcome(lambda: reader(target), names)  # noqa: B023 - called at once
        tried += 1
        if found == "accepted" and _harmless(field, mutant, HARMLESS):
            accepted.append(name)
        elif found is not None:
            failures.append(f"{name}: {found}")
    assert not failures, f"{len(failures)} of {tried}:\n" + "\n".join(failures[:40])
    print(f"{kind}: {tried} mutations, {len(accepted)} accepted as harmless")
    assert tried >= 200
    assert accepted  # the list above is not stale: these do read


@pytest.fixture
def recording(tmp_path):
    """A recording as ``imunoise record`` leaves it: log, .times, .gaps, .meta.json."""
    raw = SRC.read_bytes().splitlines(keepends=True)[:400]
    log = tmp_path / "run.txt"
    log.write_bytes(b"".join(raw))
    cut = len(b"".join(raw[:200]))
    log.with_name("run.txt.times").write_text(
        "".join(f"{len(b''.join(raw[:i]))} {1_700_000_000_000_000_000 + i * 25_000_000}\n"
                for i in range(0, 400, 50)))
    log.with_name("run.txt.gaps").write_text(f"{cut} 1700000004.0 1700000005.0\n")
    meta = {"port": "/dev/ttyUSB0", "baud": 115200,
            "identity": {"model": "VN-100T", "serial": "0100"},
            "previous": {"6": ["14"], "7": ["40"]}, "written": {"7": ["40"]},
            "fs": 40.0, "ascii": "VNYMR", "started": 1700000000.0, "seconds": 10.0,
            "bytes": log.stat().st_size, "outages": 1, "restored": True}
    log.with_name("run.txt.meta.json").write_text(json.dumps(meta))
    assert len(imunoise.read(log).gaps) == 1
    return log, meta


def test_every_mutation_of_a_recordings_metadata_is_refused(recording):
    log, meta = recording
    side = log.with_name("run.txt.meta.json")
    tried, failures = 0, []
    for name, field, mutant, text in _mutations(meta):
        side.write_text(text)
        found = _outcome(lambda: imunoise.read(log), [str(side)])
        if found is not None and field == "fs" and mutant in ("null", "missing"):
            found = _outcome(lambda: imunoise.read(log), [str(log)])  # the rate warning
        tried += 1
        harmless = _harmless(field, mutant, RECORDING_HARMLESS) or (
            field == "restored" or "." not in field and mutant == "missing")
        if found is not None and not (found == "accepted" and harmless):
            failures.append(f"{name}: {found}")
    assert not failures, f"{len(failures)} of {tried}:\n" + "\n".join(failures[:40])
    print(f"recording metadata: {tried} mutations")
    assert tried >= 100


#: Fields of a ``.gaps`` and a ``.times`` line replaced by each of these.
LINE_MUTANTS = ["inf", "-inf", "nan", "1e12", "-1", "x", "", "1 2", "0x10", "9" * 30, "1e400"]


@pytest.mark.parametrize("side", [".gaps", ".times"])
def test_every_mutation_of_a_recordings_side_lines_is_refused(recording, side):
    log, _ = recording
    path = log.with_name("run.txt" + side)
    lines = path.read_text().splitlines()
    tried, failures = 0, []
    for row in range(len(lines)):
        fields = lines[row].split()
        for col in range(len(fields)):
            for mutant in LINE_MUTANTS:
                if side == ".gaps" and col and mutant in ("-1",):
                    continue  # a negative Unix time is a valid (if odd) clock: start <= end decides
                changed = fields.copy()
                changed[col] = mutant
                text = "\n".join([*lines[:row], " ".join(changed), *lines[row + 1:]]) + "\n"
                path.write_text(text)
                found = _outcome((lambda: imunoise.read(log)) if side == ".gaps" else (
                    lambda: __import__("imunoise.readers.recording", fromlist=["x"])
                    .host_times(log)), [str(path)])
                tried += 1
                if found is not None:
                    failures.append(f"line {row + 1} field {col} = {mutant!r}: {found}")
    assert not failures, f"{len(failures)} of {tried}:\n" + "\n".join(failures[:40])
    print(f"{side}: {tried} mutations")
    assert tried >= 20
