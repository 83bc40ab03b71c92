"""The command line both rule checks share (check_layers.py, check_sizes.py): --root, the
problems one per line on stdout, their count on stderr, exit 0 clean, 1 problems, 2 bad rules."""
import argparse
import sys
from pathlib import Path


def main(doc, check, tool, what, errors=(OSError, ValueError)):
    """Runs `check(root)` (a list of problems) on the checkout --root names (default: this one)."""
    ap = argparse.ArgumentParser(description=doc.splitlines()[0])
    ap.add_argument("--root", type=Path, default=Path(__file__).resolve().parents[1])
    args = ap.parse_args()
    try:
        problems = check(args.root)
    except errors as e:
        print(f"{tool}: {e}", file=sys.stderr)
        return 2
    for p in problems:
        print(p)
    if problems:
        print(f"{len(problems)} {what} problem(s)", file=sys.stderr)
    return 1 if problems else 0
