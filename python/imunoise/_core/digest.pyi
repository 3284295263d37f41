# rust/bindings/digest.rs: the fingerprint of a file's content.

import os

def fingerprint(path: str | os.PathLike[str]) -> tuple[int, int, str]:
    """The size, modification time (ns since the epoch) and BLAKE3 digest (64 hex
    digits) of the file at ``path``."""
