"""Read material definitions from an Abaqus input file (``*Material`` blocks).

Only what skvalve needs from the Texas TriValve model (Mathur et al. 2022, CC BY-NC-SA 4.0):
each ``*Material, name=...`` with its option lines (``*Hyperelastic, OGDEN, N=3``,
``*Anisotropic Hyperelastic, user, ..., properties=4``) and their numeric data lines.
Keywords are case-insensitive in Abaqus and are lower-cased here; data continue until the
next keyword line. Malformed numbers raise ``ValueError`` naming the file and line.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["MaterialOption", "AbaqusMaterial", "read_materials", "trivalve_input"]

#: Where the shared Texas TriValve input is looked for, relative to the repository root.
TRIVALVE_RELATIVE = Path("..") / "shared" / "data" / "texas_trivalve" / "Diseased_QuasiStatic.inp"


@dataclass
class MaterialOption:
    """One option of a material: keyword (lower case), its parameters and flattened data."""

    keyword: str
    parameters: dict[str, str]
    data: list[float] = field(default_factory=list)
    line: int = 0


@dataclass
class AbaqusMaterial:
    name: str
    line: int
    options: list[MaterialOption] = field(default_factory=list)

    def option(self, keyword: str) -> MaterialOption:
        """The first option whose keyword starts with ``keyword`` (case-insensitive)."""
        for opt in self.options:
            if opt.keyword.startswith(keyword.lower()):
                return opt
        raise KeyError(f"material {self.name!r} (line {self.line}) has no *{keyword} option")


def _keyword_line(text: str) -> tuple[str, dict[str, str]]:
    parts = [p.strip() for p in text[1:].split(",")]
    params: dict[str, str] = {}
    words = [parts[0].lower()]
    for p in parts[1:]:
        if "=" in p:
            key, value = p.split("=", 1)
            params[key.strip().lower()] = value.strip()
        elif p:
            words.append(p.lower())
    return " ".join(words), params


def read_materials(path: str | os.PathLike) -> dict[str, AbaqusMaterial]:
    """All ``*Material`` blocks of an Abaqus input file, by name (case as written)."""
    path = Path(path)
    materials: dict[str, AbaqusMaterial] = {}
    current: AbaqusMaterial | None = None
    option: MaterialOption | None = None
    with path.open() as handle:
        for number, raw in enumerate(handle, start=1):
            text = raw.strip()
            if not text or text.startswith("**"):
                continue
            if text.startswith("*"):
                keyword, params = _keyword_line(text)
                option = None
                if keyword == "material":
                    if "name" not in params:
                        raise ValueError(f"{path}:{number}: *Material without name=")
                    current = AbaqusMaterial(params["name"], number)
                    materials[current.name] = current
                elif current is not None and keyword in ("step", "part", "assembly", "instance", "surface interaction"):
                    current = None
                elif current is not None:
                    option = MaterialOption(keyword, params, line=number)
                    current.options.append(option)
                continue
            if option is not None:
                for item in text.split(","):
                    item = item.strip()
                    if not item:
                        continue
                    try:
                        option.data.append(float(item))
                    except ValueError:
                        raise ValueError(f"{path}:{number}: not a number in *{option.keyword} data: {item!r}") from None
    return materials


def trivalve_input() -> Path | None:
    """The Texas TriValve input file if present: ``$SKVALVE_TRIVALVE`` or ``../shared/data/...``."""
    env = os.environ.get("SKVALVE_TRIVALVE")
    candidates = [Path(env)] if env else []
    here = Path(__file__).resolve().parents[2]
    candidates += [here / TRIVALVE_RELATIVE, Path.cwd() / TRIVALVE_RELATIVE]
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    return None
