"""Write the SSP (System Structure and Parameterization) files of the scenes.

Each scene gives ``models/systems/<scene>.ssp``: a zip with ``SystemStructure.ssd`` and the
three FMUs under ``resources/``. Components are connected component to component only (no
system-level connectors: FMPy's SSP master crashes on an unconnected one) and every
connection names ``startElement`` and ``endElement`` (libcosim needs both). The start values
of each component sit in an inline ``ssd:ParameterBindings/ssd:ParameterValues`` parameter
set named after the scene, with variable names unprefixed: libcosim and ecos apply it
themselves; FMPy's ``simulate_ssp`` ignores bindings, so :mod:`.engines` passes the same
values through its ``parameter_set`` argument (prefixed ``Component.name``).
:func:`parameter_sets` reads them back (the engines check that an SSP carries the scene's).

    python -m rotortd_cosim.ssp [SCENE ...] [--models models] [--out models/systems]

Without a scene it writes the documented scenes (``scenes.SCENES``); a variant such as
``drop_torque`` (``scenes.VARIANTS``) is written when named.
"""

from __future__ import annotations

import argparse
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path
from typing import Any
from xml.sax.saxutils import quoteattr

from .scenes import ALL_SCENES, CONNECTIONS, FMU_FILES, RECORDED, SCENES, Scene

NS = ('xmlns:ssd="http://ssp-standard.org/SSP1/SystemStructureDescription" '
      'xmlns:ssc="http://ssp-standard.org/SSP1/SystemStructureCommon" '
      'xmlns:ssv="http://ssp-standard.org/SSP1/SystemStructureParameterValues"')
Types = dict[str, dict[str, str]]
"""Component name -> {variable name: FMI type}, read from the built FMUs."""
ParameterSets = dict[str, list[tuple[str, dict[str, tuple[str, str]]]]]
"""Component name -> its parameter sets in document order: (set name, {parameter:
(SSV type, value text)})."""
_SSD = "{http://ssp-standard.org/SSP1/SystemStructureDescription}"
_SSV = "{http://ssp-standard.org/SSP1/SystemStructureParameterValues}"


def variable_types(models: Path) -> Types:
    """The type of every variable of each component, from its FMU's model description
    (the FMU's variable table is the one source of its types)."""
    from fmpy import read_model_description

    return {comp: {v.name: v.type for v in read_model_description(str(models / fmu))
                   .modelVariables} for comp, fmu in FMU_FILES.items()}


def ssv_type(fmi_type: str, value: Any) -> tuple[str, str]:
    """SSV element name and value text of a start value of the given FMI type."""
    if fmi_type == "Boolean":
        return "Boolean", "true" if value else "false"
    if fmi_type == "Integer":
        return "Integer", str(int(value))
    if fmi_type == "String":
        return "String", str(value)
    return "Real", repr(float(value))


def connectors(component: str) -> list[tuple[str, str]]:
    """(name, kind) of the connectors a component needs: connected and recorded ones."""
    found: dict[str, str] = {}
    for a, out, b, inp in CONNECTIONS:
        if a == component:
            found[out] = "output"
        if b == component:
            found[inp] = "input"
    for comp, var in RECORDED:
        if comp == component:
            found.setdefault(var, "output")
    return list(found.items())


def _component_xml(name: str, values: dict[str, Any], scene: str, types: dict[str, str]
                   ) -> str:
    conns = "\n".join(
        f'          <ssd:Connector name="{c}" kind="{k}"><ssc:{types[c]}/>'
        f"</ssd:Connector>" for c, k in connectors(name))
    params = "\n".join(
        f'                <ssv:Parameter name="{p}"><ssv:{t} value={quoteattr(v)}/>'
        f"</ssv:Parameter>" for p, (t, v) in ((p, ssv_type(types[p], x))
                                              for p, x in values.items()))
    binding = ""
    if values:
        binding = f"""
        <ssd:ParameterBindings>
          <ssd:ParameterBinding>
            <ssd:ParameterValues>
              <ssv:ParameterSet version="1.0" name="{scene}">
                <ssv:Parameters>
{params}
                </ssv:Parameters>
              </ssv:ParameterSet>
            </ssd:ParameterValues>
          </ssd:ParameterBinding>
        </ssd:ParameterBindings>"""
    return f"""      <ssd:Component name="{name}" type="application/x-fmu-sharedlibrary" \
source="resources/{FMU_FILES[name]}">
        <ssd:Connectors>
{conns}
        </ssd:Connectors>{binding}
      </ssd:Component>"""


def ssd_text(scene: Scene, types: Types) -> str:
    """SystemStructure.ssd of a scene."""
    comps = "\n".join(_component_xml(n, v, scene.name, types[n])
                      for n, v in scene.components().items())
    conns = "\n".join(
        f'      <ssd:Connection startElement="{a}" startConnector="{o}" endElement="{b}" '
        f'endConnector="{i}"/>' for a, o, b, i in CONNECTIONS)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<ssd:SystemStructureDescription {NS} version="1.0" name="{scene.name}">
  <ssd:System name="{scene.name}" description={quoteattr(scene.title)}>
    <ssd:Elements>
{comps}
    </ssd:Elements>
    <ssd:Connections>
{conns}
    </ssd:Connections>
  </ssd:System>
  <ssd:DefaultExperiment startTime="0.0" stopTime="{scene.stop_time!r}"/>
</ssd:SystemStructureDescription>
"""


def write_ssp(scene: Scene, models: Path, out_dir: Path) -> Path:
    """Write <out_dir>/<scene>.ssp (FMUs taken from models/) and <out_dir>/<scene>.ssd."""
    out_dir.mkdir(parents=True, exist_ok=True)
    text = ssd_text(scene, variable_types(models))
    (out_dir / f"{scene.name}.ssd").write_text(text, encoding="utf-8")
    path = out_dir / f"{scene.name}.ssp"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as zf:
        zf.writestr("SystemStructure.ssd", text)
        for fmu in FMU_FILES.values():
            zf.write(models / fmu, f"resources/{fmu}")
    return path


def write_all(models: Path, out_dir: Path, scenes: dict[str, Scene] | None = None
              ) -> list[Path]:
    """The SSP files of ``scenes`` (default: the documented scenes, SCENES)."""
    return [write_ssp(s, models, out_dir) for s in (SCENES if scenes is None else
                                                    scenes).values()]


def parameter_sets(ssp: Path) -> ParameterSets:
    """The inline parameter sets of every component of an SSP file (its
    ``SystemStructure.ssd``), as the engines that apply them see them."""
    with zipfile.ZipFile(ssp) as zf:
        root = ET.fromstring(zf.read("SystemStructure.ssd"))
    found: ParameterSets = {}
    for comp in root.iter(f"{_SSD}Component"):
        sets = found.setdefault(comp.get("name", ""), [])
        for pset in comp.iter(f"{_SSV}ParameterSet"):
            values = {}
            for par in pset.iter(f"{_SSV}Parameter"):
                kind = next(iter(par))
                values[par.get("name", "")] = (kind.tag.removeprefix(_SSV),
                                               kind.get("value", ""))
            sets.append((pset.get("name", ""), values))
    return found


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="write models/systems/<scene>.ssp")
    parser.add_argument("scenes", nargs="*", metavar="SCENE",
                        help=f"scenes to write, of {', '.join(ALL_SCENES)} "
                             f"(default: {', '.join(SCENES)})")
    parser.add_argument("--models", type=Path, default=Path("models"))
    parser.add_argument("--out", type=Path, default=Path("models/systems"))
    args = parser.parse_args(argv)
    unknown = [n for n in args.scenes if n not in ALL_SCENES]
    if unknown:
        parser.error(f"unknown scene {unknown[0]!r}; the scenes are "
                     f"{', '.join(ALL_SCENES)}")
    chosen = {n: ALL_SCENES[n] for n in args.scenes} if args.scenes else None
    for path in write_all(args.models, args.out, chosen):
        print(f"ssp: wrote {path}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
