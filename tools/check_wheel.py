"""Build the release wheel and prove it installs and runs where there is no Rust.

    python3 tools/check_wheel.py         # what `python3 tools/check.py wheel` runs
    python3 tools/check_wheel.py --wheel dist/imunoise-….whl   # test a wheel already built
    python3 tools/check_wheel.py --wheel dist/*.whl --expect-tag manylinux_2_17_x86_64

1. ``maturin build --release`` (abi3: one ``cp310-abi3`` wheel for CPython >= 3.10). On
   Linux with Zig available (``pip install ziglang``) the wheel is built as the release
   workflow ships it, ``--zig --compatibility manylinux2014``: linked against glibc 2.17
   whatever this machine's glibc, and the check asserts the ``manylinux_2_17`` tag (the
   file name, and ``auditwheel show`` when auditwheel is installed). Without Zig it is
   built for this machine's glibc (fine here, not for publishing) and no tag is asserted;
2. a fresh venv, entered with an environment that has no Rust: PATH without any folder
   holding cargo, rustc or rustup, and no CARGO_*/RUSTUP_* variables (checked);
3. ``pip install`` the wheel (its dependencies from the package index) in that venv;
4. a smoke import from outside the source tree (the module must come from the venv),
   ``imunoise --version``, ``imunoise.__version__`` and the wheel's metadata must agree;
5. ``imunoise demo`` into a temporary folder: the report must be written.

The release build takes several minutes on two cores (fat LTO); CARGO_TARGET_DIR is
honoured.
"""

from __future__ import annotations

import argparse
import os
import platform
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
RUST_TOOLS = ("cargo", "rustc", "rustup")
#: Where a venv keeps its programs.
BIN = "Scripts" if os.name == "nt" else "bin"
#: Variables the venv's commands keep: certificates, proxies, pip's settings, locale.
KEPT = ("HOME", "LANG", "LC_ALL", "TMPDIR", "SSL_CERT_FILE", "SSL_CERT_DIR",
        "REQUESTS_CA_BUNDLE", "CURL_CA_BUNDLE", "SYSTEMROOT", "TEMP", "TMP", "USERPROFILE")
KEPT_PREFIXES = ("PIP_", "HTTP_PROXY", "HTTPS_PROXY", "NO_PROXY", "http_proxy", "https_proxy",
                 "no_proxy")

SMOKE = """
import importlib.metadata, sys
import numpy as np
import imunoise
assert "site-packages" in imunoise.__file__, imunoise.__file__
assert imunoise._core.__file__.endswith(".abi3.so") or sys.platform == "win32", \\
    imunoise._core.__file__
meta = importlib.metadata.version("imunoise")
assert imunoise.__version__ == meta, (imunoise.__version__, meta)
x = imunoise.simulate(20_000, 100.0, N=1e-3, seed=0)
r = imunoise.adev(x, 100.0)
model = imunoise.fit(r, terms=["N"])
assert abs(float(model.N) / 1e-3 - 1) < 0.1, model.N
print(f"smoke: imunoise {meta} from {imunoise.__file__}; N = {float(model.N):.4g}")
"""


def run(command: list[str], **kwargs) -> None:
    print(f"$ {' '.join(str(c) for c in command)}", flush=True)
    subprocess.run(command, check=True, **kwargs)


def zig_available() -> bool:
    """Zig for maturin's ``--zig``: on PATH or as the ziglang package."""
    import importlib.util

    return bool(shutil.which("zig")) or importlib.util.find_spec("ziglang") is not None


def manylinux2014_tag() -> str | None:
    """The tag a manylinux2014 wheel of this machine carries, or None off Linux."""
    if not sys.platform.startswith("linux"):
        return None
    return f"manylinux_2_17_{platform.machine()}"


def build(out: Path, *, zig: bool) -> Path:
    command = ["maturin", "build", "--release", "--out", str(out)]
    if zig:
        command += ["--zig", "--compatibility", "manylinux2014"]
    run(command, cwd=ROOT)
    wheels = sorted(out.glob("imunoise-*.whl"))
    if len(wheels) != 1:
        raise SystemExit(f"check_wheel: expected one wheel in {out}; got {wheels}")
    return wheels[0]


def check_tag(wheel: Path, tag: str) -> None:
    """The wheel's file name carries ``tag``, and auditwheel (when installed) agrees
    that the shared library needs nothing newer."""
    if tag not in wheel.name.removesuffix(".whl").split("-")[-1].split("."):
        raise SystemExit(f"check_wheel: {wheel.name} is not tagged {tag}")
    import importlib.util

    if importlib.util.find_spec("auditwheel") is None:
        print(f"tag ok: {tag} (file name; auditwheel not installed)")
        return
    shown = subprocess.run([sys.executable, "-m", "auditwheel", "show", str(wheel)],
                           check=True, capture_output=True, text=True).stdout
    found = re.search(r'consistent with the following platform tag:\s*"([^"]+)"',
                      " ".join(shown.split()))
    if found is None or found.group(1) != tag:
        raise SystemExit(f"check_wheel: auditwheel says {found and found.group(1)!r}, "
                         f"not {tag!r}:\n{shown}")
    print(f"tag ok: {tag} (file name and auditwheel show)")


def without_rust(venv: Path) -> dict[str, str]:
    """The environment of the venv's commands: no Rust tool reachable."""
    folders = [str(venv / BIN)] + [
        d for d in os.environ.get("PATH", "").split(os.pathsep)
        if d and not any(shutil.which(tool, path=d) for tool in RUST_TOOLS)
    ]
    env = {k: v for k, v in os.environ.items()
           if k in KEPT or k.startswith(KEPT_PREFIXES)}
    env["PATH"] = os.pathsep.join(folders)
    env["VIRTUAL_ENV"] = str(venv)
    found = [t for t in RUST_TOOLS if shutil.which(t, path=env["PATH"])]
    if found:
        raise SystemExit(f"check_wheel: {', '.join(found)} still on PATH")
    return env


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wheel", type=Path, help="test this wheel instead of building one")
    parser.add_argument("--expect-tag", metavar="TAG",
                        help="platform tag the wheel must carry, e.g. manylinux_2_17_x86_64 "
                             "(default: asserted only for a wheel built here with Zig)")
    parser.add_argument("--no-zig", action="store_true",
                        help="build for this machine's glibc even where Zig is available")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="imunoise-wheel-") as tmp:
        tmp = Path(tmp)
        tag = args.expect_tag
        if args.wheel:
            wheel = args.wheel.resolve()
        else:
            zig = (not args.no_zig and manylinux2014_tag() is not None and zig_available())
            if not zig:
                print("check_wheel: no Zig (or not Linux): the wheel is built for this "
                      "machine only and its tag is not checked", flush=True)
            wheel = build(tmp / "dist", zig=zig)
            tag = tag or (manylinux2014_tag() if zig else None)
        if "-cp310-abi3-" not in wheel.name:
            raise SystemExit(f"check_wheel: {wheel.name} is not an abi3 (cp310-abi3) wheel")
        if tag:
            check_tag(wheel, tag)
        venv = tmp / "venv"
        run([sys.executable, "-m", "venv", str(venv)])
        env = without_rust(venv)
        python = str(venv / BIN / "python")
        work = tmp / "work"  # outside the source tree: nothing imports from python/
        work.mkdir()
        run([python, "-m", "pip", "install", "--quiet", str(wheel)], env=env, cwd=work)
        run([python, "-c", SMOKE], env=env, cwd=work)
        imunoise = str(venv / BIN / "imunoise")
        version = subprocess.run([imunoise, "--version"], env=env, cwd=work, check=True,
                                 capture_output=True, text=True).stdout.strip()
        meta = subprocess.run([python, "-c", "import imunoise; print(imunoise.__version__)"],
                              env=env, cwd=work, check=True, capture_output=True,
                              text=True).stdout.strip()
        if version != f"imunoise {meta}" or meta not in wheel.name:
            raise SystemExit(f"check_wheel: versions differ: {version!r}, __version__ "
                             f"{meta!r}, wheel {wheel.name}")
        print(f"versions agree: {version}, {wheel.name}")
        run([imunoise, "demo", "-o", str(tmp / "demo"), "--no-progress"], env=env, cwd=work)
        if not (tmp / "demo" / "report.html").exists():
            raise SystemExit("check_wheel: imunoise demo wrote no report.html")
        print(f"wheel ok: {wheel.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
