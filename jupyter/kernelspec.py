#!/usr/bin/env python3
"""The kernel spec named `sicm`: writing it, and installing it where Jupyter looks.

    python kernelspec.py --sicm /abs/build/sicm [--prefix DIR | --user]

installs the spec with jupyter_client's KernelSpecManager: --prefix DIR puts
it under DIR/share/jupyter/kernels/sicm (a virtual environment's prefix,
which that environment's `jupyter` searches); --user puts it in the user's
Jupyter data directory (~/.local/share/jupyter/kernels/sicm, or
$JUPYTER_DATA_DIR/kernels/sicm when that is set), which every `jupyter` the
user runs searches. The spec runs sicm_kernel.py (beside this file) with the
Python running this script, and names the sicm binary by absolute path in
its environment (SICM_BINARY), so the kernel finds both wherever Jupyter is
started from. The tests write the same spec into a directory of their own
(tests/jupyter/).
"""

import argparse
import json
import os
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))


def kernel_spec(python, sicm):
    """The contents of kernel.json for a kernel run by `python`, on `sicm`."""
    return {
        "argv": [python, os.path.join(HERE, "sicm_kernel.py"), "-f", "{connection_file}"],
        "display_name": "sicm",
        "language": "scheme",
        "interrupt_mode": "signal",
        # PYDEVD_...: ipykernel's debugger would warn on every start about Python
        # 3.11's frozen modules, a warning about debugging that nobody asked for.
        "env": {"SICM_BINARY": os.path.abspath(sicm), "PYDEVD_DISABLE_FILE_VALIDATION": "1"},
    }


def write_kernel_spec(directory, python, sicm):
    """Write kernel.json into `directory` (made if missing)."""
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, "kernel.json"), "w") as f:
        json.dump(kernel_spec(python, sicm), f, indent=2)
        f.write("\n")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sicm", required=True, help="the sicm binary")
    where = ap.add_mutually_exclusive_group(required=True)
    where.add_argument("--prefix", help="install under PREFIX/share/jupyter/kernels")
    where.add_argument("--user", action="store_true", help="install in the user's data dir")
    a = ap.parse_args()
    if not os.access(a.sicm, os.X_OK):
        sys.exit(f"kernelspec.py: {a.sicm} is not an executable (run `make` first)")

    from jupyter_client.kernelspec import KernelSpecManager

    with tempfile.TemporaryDirectory() as tmp:
        source = os.path.join(tmp, "sicm")
        write_kernel_spec(source, sys.executable, a.sicm)
        dest = KernelSpecManager().install_kernel_spec(
            source, "sicm", user=a.user, prefix=None if a.user else a.prefix)
    print(f"installed the kernel spec sicm in {dest}")


if __name__ == "__main__":
    main()
