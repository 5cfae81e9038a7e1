"""Makes bindings/python importable; the library comes from VSTREE_LIBRARY (set by run.sh)."""
import os
import sys

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "bindings", "python"))
