"""results/index.md: one page linking the report of every study of ``make study``.

    python studies/index.py RESULTS NAME [NAME ...]

Each NAME is a directory of RESULTS holding a report.md (a sweep study) or
modes.md (the modal table); the first paragraph of each is quoted.
"""
from __future__ import annotations

import json
import sys
from pathlib import Path


def entry(results: Path, name: str) -> list[str]:
    folder = results / name
    page = next(p for p in (folder / "report.md", folder / f"{name}.md") if p.exists())
    lines = page.read_text().splitlines()
    title = lines[0].lstrip("# ")
    first = next((x for x in lines[1:] if x.strip()), "")
    prov = folder / "provenance.json"
    extra = ""
    if prov.exists():
        info = json.loads(prov.read_text())
        runs = info.get("runs") or []
        if runs:
            extra = f" (last sweep: {runs[-1]['points_run']} points in {runs[-1]['wall_s']:.0f} s wall)"
    return [f"- [{title}]({page.relative_to(results)}): {first}{extra}"]


def main(argv: list[str]) -> None:
    results = Path(argv[0])
    lines = ["# Results of `make study`", ""]
    for name in argv[1:]:
        lines += entry(results, name)
    (results / "index.md").write_text("\n".join(lines) + "\n")
    print(results / "index.md")


if __name__ == "__main__":
    main(sys.argv[1:])
