"""``python -m flex.sweep``: the old entry point, now one line saying where it went."""

import sys

if __name__ == "__main__":
    print("flex: error: python -m flex.sweep is now part of 'flex run': run 'flex run STUDY' "
          "(or 'python -m flex run STUDY') with --scheduler, --workers, --folder, "
          "--retry-failed", file=sys.stderr)
    raise SystemExit(2)
