import os
import pathlib

import pytest
from helpers.data import DATA
from hypothesis import settings

# CI explores a fixed set of examples per property (a rare case found by chance must
# not turn a run red without a change); local runs keep drawing new ones.
settings.register_profile("ci", derandomize=True, print_blob=True)
if os.environ.get("CI"):
    settings.load_profile("ci")

@pytest.fixture(scope="session")
def data_dir() -> pathlib.Path:
    return DATA
