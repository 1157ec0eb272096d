"""``*Material`` blocks: the options (``*Density``, ``*Hyperelastic``, ...) and their numeric data.

Each option's data are read strictly (see :mod:`.lexer`): a blank field is Abaqus's default 0 and keeps
its position, and the number of values must be what the option declares, e.g. ``3N`` for
``*Hyperelastic, OGDEN, N=N`` or ``P`` for ``properties=P`` (temperature-dependent tables are not
supported and are rejected by that count). Material names are case-insensitive: a second material
whose name differs only in case is an error.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from .lexer import Card, data_values, parse_int

__all__ = ["MaterialOption", "AbaqusMaterial", "MATERIAL_OPTIONS", "read_material_option"]

#: Keywords that are options of the ``*Material`` above them.
MATERIAL_OPTIONS = frozenset({
    "density", "elastic", "hyperelastic", "anisotropic hyperelastic", "hyperfoam", "user material", "depvar",
    "transverse shear", "damping", "expansion", "viscoelastic", "plastic", "conductivity", "specific heat",
    "user defined field",
})
_HYPERELASTIC_COUNTS = {"neo hooke": 2, "mooney-rivlin": 3, "yeoh": 6, "arruda-boyce": 3, "van der waals": 5}
_ELASTIC_COUNTS = {"isotropic": 2, "engineering constants": 9, "orthotropic": 9, "anisotropic": 21,
                   "lamina": 6, "traction": 3}


@dataclass
class MaterialOption:
    """One option of a material: keyword with its flags (lower case), its parameters and its data."""

    keyword: str
    parameters: dict[str, str]
    data: list[float] = field(default_factory=list)
    line: int = 0


@dataclass
class AbaqusMaterial:
    """A ``*Material``: name as written, line of the keyword and its options in file order."""

    name: str
    line: int
    options: list[MaterialOption] = field(default_factory=list)

    def option(self, keyword: str) -> MaterialOption:
        """The first option whose keyword starts with ``keyword`` (case-insensitive)."""
        for opt in self.options:
            if opt.keyword.startswith(keyword.lower()):
                return opt
        raise KeyError(f"material {self.name!r} (line {self.line}) has no *{keyword} option")


def _count_parameter(card: Card, name: str, default: int) -> int:
    text = card.parameters.get(name)
    if text is None:
        return default
    value = parse_int(text, card, card.location, f"{name.upper()}=")
    if value < 0 or value > 10_000:
        raise card.error(f"{name.upper()}={value} is out of range")
    return value


def expected_count(card: Card) -> tuple[int, str] | None:
    """Number of data values ``card`` declares, with the rule in words; None when not checked."""
    kind = card.keyword
    flags = set(card.flags)
    if kind in ("density", "depvar"):
        return 1, f"*{card.title} takes 1 value"
    if kind == "transverse shear":
        return 3, "*Transverse Shear takes K11, K22, K12"
    if kind == "user material":
        n = _count_parameter(card, "constants", 0)
        return n, f"CONSTANTS={n}"
    if kind == "elastic":
        elastic_type = card.parameters.get("type", "isotropic").lower()
        if elastic_type in _ELASTIC_COUNTS:
            return _ELASTIC_COUNTS[elastic_type], f"*Elastic, TYPE={elastic_type.upper()}"
        return None
    if kind == "anisotropic hyperelastic":
        if "user" in flags:
            n = _count_parameter(card, "properties", 0)
            return n, f"PROPERTIES={n}"
        return None
    if kind == "hyperelastic":
        if "user" in flags:
            n = _count_parameter(card, "properties", 0)
            return n, f"PROPERTIES={n}"
        if "test data input" in flags:
            return None
        if "ogden" in flags:
            n = _count_parameter(card, "n", 1)
            return 3 * n, f"3N for OGDEN, N={n}"
        if "reduced polynomial" in flags:
            n = _count_parameter(card, "n", 1)
            return 2 * n, f"2N for REDUCED POLYNOMIAL, N={n}"
        for name, count in _HYPERELASTIC_COUNTS.items():
            if name in flags:
                return count, name.upper()
        n = _count_parameter(card, "n", 1)
        return n * (n + 3) // 2 + n, f"POLYNOMIAL, N={n}"
    return None


def read_material_option(card: Card) -> MaterialOption:
    """The option of ``card`` with its data checked against the count the option declares."""
    values = data_values(card, blank=0.0)
    expected = expected_count(card)
    if expected is not None and len(values) != expected[0]:
        where = card.data[-1].location if card.data else card.location
        raise card.error(
            f"expected {expected[0]} data values ({expected[1]}), found {len(values)}"
            " (data cut short, or temperature-dependent data, which is not supported)", where)
    keyword = " ".join([card.keyword, *card.flags])
    return MaterialOption(keyword, dict(card.parameters), values, line=card.location.line)
