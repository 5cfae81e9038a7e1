"""Shared set-up of the Python peers of the table benches (`benches/peers.py` for Table 1,
`benches/reconstruct_peers.py` for Table 2); a module, not a script.

A peer script calls `ensure(...)` first: outside the virtual environment `target/bench-venv` it
creates it (on first use), installs the pinned packages the script needs, installs missing
system libraries (libGL and friends) with apt-get when it can, and re-runs the script inside
the venv. Packages marked optional may fail to install: the script then runs without them and
says so. Set `PEERS_NO_SETUP=1` to skip all this and use whatever `python3` has.
"""

import importlib
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VENV = ROOT / "target" / "bench-venv"
# Shared libraries that the peers' wheels expect from the system, and their Debian packages.
SYSTEM_LIBS = {
    "libGL.so.1": "libgl1",
    "libGLX.so.0": "libglx0",
    "libOpenGL.so.0": "libopengl0",
    "libGLU.so.1": "libglu1-mesa",
    "libX11.so.6": "libx11-6",
    "libxcb.so.1": "libxcb1",
    "libgomp.so.1": "libgomp1",
    "libusb-1.0.so.0": "libusb-1.0-0",
}


def log(message):
    """Writes a diagnostic line to stderr, prefixed with the running script's name."""
    print(f"{Path(sys.argv[0]).name}: {message}", file=sys.stderr, flush=True)


def venv_python():
    return VENV / "bin" / "python"


def in_venv():
    return Path(sys.prefix).resolve() == VENV.resolve()


def import_error(module, python=None):
    """Runs `import <module>` in `python` (default: this interpreter, in a child); returns None
    on success, else the error text."""
    probe = subprocess.run(
        [str(python or sys.executable), "-c", f"import {module}"], capture_output=True, text=True
    )
    return None if probe.returncode == 0 else (probe.stderr.strip() or "import failed")


def apt_install(packages):
    """Installs Debian packages, as root or through sudo; returns whether it worked."""
    if shutil.which("apt-get") is None:
        return False
    prefix = [] if os.geteuid() == 0 else (["sudo", "-n"] if shutil.which("sudo") else None)
    if prefix is None:
        return False
    log(f"installing system packages: {' '.join(packages)}")
    env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
    for command in (["apt-get", "update", "-q"], ["apt-get", "install", "-y", "-q", *packages]):
        if subprocess.run(prefix + command, env=env, stdout=sys.stderr).returncode != 0:
            return False
    return True


def failure_note(spec):
    """Where a failed optional install is remembered, so later runs do not retry it."""
    return VENV / f"failed-{re.sub(r'[^A-Za-z0-9_.-]', '_', spec)}.txt"


def install(python, module, spec):
    """Makes `import <module>` work in `python`: pip-installs `spec` if the module is missing,
    then installs the system libraries it fails to load. Returns None or the error text."""
    error = import_error(module, python)
    if error is not None and "No module named" in error:
        log(f"installing {spec} into {VENV}")
        pip = subprocess.run(
            [str(python), "-m", "pip", "install", "-q", "--disable-pip-version-check", spec],
            stdout=sys.stderr,
        )
        if pip.returncode != 0:
            return f"pip install {spec} failed (exit status {pip.returncode})"
        error = import_error(module, python)
    for _ in range(len(SYSTEM_LIBS)):
        if error is None:
            break
        missing = re.findall(r"(lib[\w+.-]+\.so[.\d]*): cannot open shared object", error)
        packages = sorted({SYSTEM_LIBS[m] for m in missing if m in SYSTEM_LIBS})
        if not packages or not apt_install(packages):
            break
        error = import_error(module, python)
    return error


def ensure(required, optional=()):
    """Runs the calling script inside the venv with its packages: `required` and `optional` are
    lists of (module, pinned pip spec). A required package that cannot be imported ends the
    script; an optional one is left out (see `optional_import`). Returns only when already in
    the venv or when PEERS_NO_SETUP=1; otherwise re-executes the script in the venv."""
    if in_venv() or os.environ.get("PEERS_NO_SETUP") == "1":
        return
    python = venv_python()
    if not python.exists():
        log(f"creating {VENV}")
        subprocess.run([sys.executable, "-m", "venv", str(VENV)], check=True)
    for module, spec in required:
        error = install(python, module, spec)
        if error is not None:
            sys.exit(f"{Path(sys.argv[0]).name}: cannot import {module} in {VENV}:\n{error}")
    for module, spec in optional:
        note = failure_note(spec)
        if note.exists():
            continue
        error = install(python, module, spec)
        if error is not None:
            log(f"{spec} unavailable, going on without it (delete {note} to retry):\n{error}")
            note.write_text(error.splitlines()[-1] + "\n")
    script = Path(sys.argv[0]).resolve()
    os.execv(str(python), [str(python), str(script), *sys.argv[1:]])


def optional_import(module, spec):
    """Imports an optional package: (module, None), or (None, why it cannot be used, one line)."""
    note = failure_note(spec)
    if note.exists() and os.environ.get("PEERS_NO_SETUP") != "1":
        return None, note.read_text().strip()
    try:
        return importlib.import_module(module), None
    except (ImportError, OSError) as error:
        return None, f"{type(error).__name__}: {error}"
