"""The real bearing's twelve parameters on the command line (docs/model.md §10,
docs/bearing.md): which option each belongs to, and the rules ``rotortd sweep`` and
``rotortd simulate`` check before running.

- Every option and parameter needs the spin as a state: ``J`` in a sweep, ``integrate_spin =
  true`` in the FMU (the race's spin and the contact torque act on the rotor's spin).
- A parameter of an option has an effect only with its option on: giving it with its option
  off (or not given: every option is off by default) is refused.
- Options are Booleans: 0/1 (``true``/``false`` for ``rotortd simulate``).
"""

from __future__ import annotations

from collections.abc import Mapping

OPTIONS: dict[str, tuple[str, ...]] = {
    "race_turns": ("J_b", "T_b0", "c_bw", "omega_b0"),
    "support_compliant": ("m_b", "k_b", "c_b"),
    "contact_compliant": ("k_c", "p_c"),
}
"""Each option (Boolean) and the parameters it switches on."""
OPTION_OF = {name: opt for opt, names in OPTIONS.items() for name in names}
BEARING_NAMES: tuple[str, ...] = tuple(n for opt, ps in OPTIONS.items() for n in (opt, *ps))
"""The twelve names, in docs/model.md §10's order."""
UNITS = {"J_b": "kg m^2", "T_b0": "N m", "c_bw": "N m s", "omega_b0": "rad/s", "m_b": "kg",
         "k_b": "N/m", "c_b": "N s/m", "k_c": "N/m", "p_c": "1"}


def bearing_problems(given: Mapping[str, object], spin_is_state: bool, how_spin: str,
                     how_option: str) -> list[str]:
    """Messages for the bearing names in ``given`` (name -> value, or -> None when the
    option is swept and so on at some points): spin not a state (``how_spin`` says how to
    make it one), or a parameter whose option is off (``how_option`` formats the fix, with
    ``{opt}``). Empty when all is well."""
    names = [n for n in BEARING_NAMES if n in given]
    problems: list[str] = []
    if names and not spin_is_state:
        problems.append(
            f"{', '.join(names)}: the real bearing (docs/model.md §10) needs the spin as a "
            f"state: {how_spin}")
    for name in names:
        opt = OPTION_OF.get(name)
        if opt is not None and given.get(opt, False) in (False, 0, 0.0):
            problems.append(
                f"{name} has no effect with {opt} off (every option is off unless given): "
                + how_option.format(opt=opt))
    return problems
