"""Readers that turn logs into :class:`ImuLog` objects."""

from imunoise.readers.grid import Gaps
from imunoise.readers.log import CHANNELS, DEFAULT_FS, ISSUE_KINDS, ImuLog, ParseIssues

__all__ = ["CHANNELS", "DEFAULT_FS", "ISSUE_KINDS", "Gaps", "ImuLog", "ParseIssues"]
