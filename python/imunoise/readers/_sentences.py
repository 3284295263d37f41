"""Raw VN sentences carried inside other containers (a CSV column, a ROS message field).

The CSV and ROS-bag readers meet logs whose every row or message carries one VN-100
ASCII sentence next to a timestamp. This module is the one place where they call the
VN parser (:func:`imunoise.readers.vn.parse_vn_sentences`): it joins the sentences into
one LF-separated stream, parses it in one call, lines each decoded sample up with the
row or message it came from, and translates the parser's line numbers back into the
container's own locations (CSV line numbers, 1-based message numbers).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from imunoise._core import vn as _core_vn
from imunoise.errors import ImunoiseValueError
from imunoise.readers.log import CHANNELS, ISSUE_KINDS, ImuLog, ParseIssues

#: How many locations per issue kind a reader keeps in ``ParseIssues.first``: the
#: VN parser's number, so ``first`` means the same for every reader.
MAX_FIRST = _core_vn.FIRST_KEEP


def parse_sentences(data: bytes, *, strict: bool, source: str) -> ImuLog:
    """Parse a stream of ``$VN...*hh`` sentences (the only call into the VN parser).

    Raises
    ------
    ImportError
        When the VN ASCII parser is not available in this build.
    """
    from imunoise.readers.vn import parse_vn_sentences

    # fs is a placeholder: the caller computes the rate from its own timestamps.
    return parse_vn_sentences(data, strict=strict, fs=1.0, source=source)


class IssueTally:
    """Mutable counts and first locations, frozen into :class:`ParseIssues` at the end."""

    def __init__(self) -> None:
        self.counts = dict.fromkeys(ISSUE_KINDS, 0)
        self.first: dict[str, list[int]] = {kind: [] for kind in ISSUE_KINDS}

    def issues(self, location: str) -> ParseIssues:
        """Frozen counts; the kept locations in increasing order."""
        first = {kind: sorted(v) for kind, v in self.first.items()}
        return ParseIssues(counts=self.counts, first=first, location=location)

    def add(self, kind: str, location: int | None = None, count: int = 1) -> None:
        self.counts[kind] += count
        if location is not None and len(self.first[kind]) < MAX_FIRST:
            self.first[kind].append(int(location))


@dataclass
class SentenceRows:
    """Samples decoded from one sentence per item, aligned with the items."""

    channels: dict[str, np.ndarray]  # decoded channels, one row per kept item
    kept: np.ndarray  # indices of the items that gave exactly one sample
    time: np.ndarray | None  # the VN sentences' own time, if they carry one
    messages: dict[str, int]


def sentence_rows(
    items: Sequence[bytes],
    locations: Sequence[int],
    tally: IssueTally,
    *,
    strict: bool,
    source: str,
    where: str = "line",
) -> SentenceRows:
    """Decode one VN sentence per item and say which items gave a sample.

    Parameters
    ----------
    items : sequence of bytes
        The text of the field that carries the sentence, one per row or message.
    locations : sequence of int
        Where each item is in the container (CSV line number, message number);
        issues are reported at these locations.
    tally : IssueTally
        Receives the parser's issues, moved to ``locations``.
    strict : bool
        Raise ``ValueError`` naming the container location at the first bad item.
    where : str
        Word for a location in error messages (``"line"``, ``"message"``).
    """
    locations = np.asarray(locations, dtype=np.int64)
    clean = []
    keep_in = []
    for i, item in enumerate(items):
        start = item.find(b"$VN")
        if start < 0:
            if strict:
                if clean:  # a bad sentence on an earlier item is reported first
                    sentence_rows(
                        items[:i],
                        locations[:i],
                        IssueTally(),
                        strict=True,
                        source=source,
                        where=where,
                    )
                raise ImunoiseValueError(
                    f"{source}: {where} {locations[i]}: no $VN sentence in the field")
            tally.add("malformed_field", locations[i])
            continue
        # one item per line: a line break inside the field would shift the line numbers
        clean.append(item[start:].replace(b"\r", b" ").replace(b"\n", b" ").rstrip())
        keep_in.append(i)
    keep_in = np.asarray(keep_in, dtype=np.int64)
    empty = SentenceRows({}, np.zeros(0, dtype=np.int64), None, {})
    if not clean:
        return empty
    data = b"\n".join(clean) + b"\n"
    line_loc = locations[keep_in]
    try:
        log = parse_sentences(data, strict=strict, source=source)
    except ValueError as exc:
        match = re.search(r"line (\d+)", str(exc))
        if match and 1 <= int(match.group(1)) <= len(line_loc):
            loc = line_loc[int(match.group(1)) - 1]
            raise ImunoiseValueError(f"{source}: {where} {loc}: {exc}") from exc
        for k, c in enumerate(clean):  # the message names no line: find the item
            try:
                parse_sentences(c + b"\n", strict=True, source=source)
            except ValueError as item_exc:
                raise ImunoiseValueError(f"{source}: {where} {line_loc[k]}: {item_exc}") from exc
        raise ImunoiseValueError(f"{source}: {exc}") from exc

    # move the parser's issues from lines of `data` to container locations
    starts = np.concatenate(([0], np.cumsum([len(c) + 1 for c in clean])))
    for kind in ISSUE_KINDS:
        count = log.issues.counts[kind]
        if not count:
            continue
        firsts = []
        for pos in log.issues.first[kind]:
            if log.issues.location == "byte":
                k = int(np.searchsorted(starts, pos, side="right")) - 1
            else:
                k = int(pos) - 1
            if 0 <= k < len(line_loc):
                firsts.append(int(line_loc[k]))
        tally.counts[kind] += count
        tally.first[kind] = (tally.first[kind] + firsts)[:MAX_FIRST]

    n = len(log)
    if n == len(clean):
        per_item = np.ones(len(clean), dtype=np.int64)
    else:
        # rare path (some item gave no sample, or several): find out which, item by item
        per_item = np.zeros(len(clean), dtype=np.int64)
        for k, c in enumerate(clean):
            per_item[k] = len(parse_sentences(c + b"\n", strict=False, source=source))
        if int(per_item.sum()) != n:
            raise RuntimeError(
                f"{source}: VN parser gave {n} samples in one pass and "
                f"{int(per_item.sum())} sentence by sentence"
            )
        # items with no sample the parser did not count as a bad record
        silent = np.flatnonzero(per_item == 0)
        for k in silent[: max(0, len(silent) - log.issues.total)]:
            tally.add("malformed_field", line_loc[k])
        for k in np.flatnonzero(per_item > 1):
            tally.add("malformed_field", line_loc[k])  # several sentences in one field
    first_row = np.concatenate(([0], np.cumsum(per_item)[:-1]))
    single = np.flatnonzero(per_item == 1)
    rows = first_row[single]
    channels = {
        name: np.asarray(getattr(log, name))[rows]
        for name in CHANNELS
        if getattr(log, name) is not None
    }
    time = None if log.time is None else np.asarray(log.time)[rows]
    messages = dict(log.messages)
    return SentenceRows(channels, keep_in[single], time, messages)
