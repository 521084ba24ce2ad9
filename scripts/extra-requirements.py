"""Prints, one per line, the requirements an installed distribution declares for its base
install plus the given extras: what `pip install "dist[extra,...]"` would add.

Usage: python scripts/extra-requirements.py DIST [EXTRA ...]

Only the markers maturin writes for extras (`extra == "name"`) are understood; any other
marker is an error, so a requirement is never dropped silently.
"""

import re
import sys
from importlib.metadata import requires


def main() -> None:
    dist, extras = sys.argv[1], set(sys.argv[2:])
    for text in requires(dist) or []:
        spec, _, marker = text.partition(";")
        marker = marker.strip()
        if not marker:
            print(spec.strip())
            continue
        m = re.fullmatch(r"extra\s*==\s*['\"]([^'\"]+)['\"]", marker)
        if m is None:
            sys.exit(f"extra-requirements: marker not understood: {text!r}")
        if m.group(1) in extras:
            print(spec.strip())


if __name__ == "__main__":
    main()
