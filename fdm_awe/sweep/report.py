"""All outputs of a sweep from its records: table, plots, summary, JSON document."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, Sequence

from ..fileio import atomic_write_text
from .outputs import answer, answer_sentence, cold_check_differences, folding_cells, folding_map_plot, power_curve_plot, summary_markdown, write_csv
from .references import ReferenceCurves, reference_curves, tether_properties
from .spec import SweepSpec

#: stated in every summary: what the design variants keep fixed
NOTES = (
    "Energies are counted as the scenario defines them (physical: electrically at the generator load and the "
    "motor supply, propeller drive power with airspeed, tether drag).",
    "Folded-wing variants: S_f = b_f x chord, Helmbold lift slope at A_f = b_f/chord, Oswald factor, zero-lift "
    "angle and C_Lmax of the folded definition, C_Dmin from the folded drag area; mass and inertia unchanged.",
    "Foldable points fold over the fold time of their record (fold_time_s; 0 = an instantaneous switch).",
    "Loyd and quasi-steady curves are reel-out (mechanical) powers without losses or recovery: upper references, "
    "not cycle averages.",
)


@dataclass
class SweepReport:
    """Paths of the written outputs and the answer."""

    files: dict[str, str]
    answer: dict[str, Any]
    sentence: str
    refs: ReferenceCurves | None
    markdown: str
    cold_check: dict[str, Any] | None = None  #: :func:`~.outputs.cold_check_differences` of the records


def spec_references(spec: SweepSpec) -> ReferenceCurves:
    """Reference curves for the sweep's first wing area, tether range and tether line (its first
    diameter for the sized line), over its winds."""
    from .design import Design, design_glider
    from .runner import base_glider, point_ground_station

    base = base_glider(spec.aircraft)
    g = design_glider(base, Design(wing_area=spec.wing_areas[0]))
    line = spec.line_names()[0]
    d, cdp = tether_properties(line, spec.line_diameters[0] if line == "sized" else None,
                               point_ground_station(spec.ground_station))
    d0, dtf = spec.tether_ranges[0]
    winds = sorted(set(spec.winds))
    return reference_curves(winds, g.unfolded.aero, d, cdp, d0, dtf)


def plant_note(spec: SweepSpec) -> str:
    """What every point of ``spec`` models of the plant: tether lines, propeller, line weight."""
    plant = spec.plant()
    lines = ", ".join(spec.line_names())
    dia = [d for d in spec.line_diameters if d is not None]
    if dia and "sized" in spec.line_names():
        lines += " (sized line also resized to d_t = " + ", ".join(f"{1e3 * d:.3g}" for d in dia) + " mm)"
    if spec.scenario != "physical":
        return f"Plant model: tether line {lines} (the paper scenario's line has no drag or weight in the optimiser)."
    return (f"Plant model: tether line {lines}; propeller {plant['propeller']}; line weight on the glider "
            f"{'on' if plant['line_weight'] else 'off'}.")


def wind_note(spec: SweepSpec) -> str:
    """How the sweep's wind varies with height, and at which height its wind speeds hold."""
    from ..wind import WindProfile

    prof = WindProfile.parse(spec.wind_profile, option="wind profile")
    if prof.uniform:
        return "Wind: uniform (the same speed at every height)."
    return (f"Wind: {prof.describe()}; every wind speed of this sweep (table, plot, references) is the speed at "
            f"{prof.ref_height:g} m, the glider meets the profile's speed at its own height (the Loyd and "
            f"quasi-steady references use the {prof.ref_height:g} m speed).")


def output_files(out_dir: str | Path) -> dict[str, Path]:
    """The files :func:`write_outputs` writes into ``out_dir`` (``folding_map`` only when the
    sweep has foldable points)."""
    out = Path(out_dir)
    return {"table": out / "points.csv", "power_curve": out / "power_curve.png", "folding_map": out / "folding_map.png",
            "summary": out / "summary.md"}


def write_outputs(spec: SweepSpec, records: Sequence[dict[str, Any]], out_dir: str | Path) -> SweepReport:
    """Write ``points.csv``, ``power_curve.png``, ``folding_map.png`` (if foldable points),
    ``summary.md`` into ``out_dir`` (each atomically: temporary name, then renamed)."""
    paths = output_files(out_dir)
    refs = spec_references(spec)
    files = {"table": str(write_csv(records, paths["table"]))}
    title = f"{spec.scenario} scenario, mesh {spec.mesh.n_gen}/{spec.mesh.n_rec}, degree {spec.mesh.degree}"
    wind_label = "wind speed [m/s]"
    if spec.wind_profile != "uniform":
        from ..wind import WindProfile

        prof = WindProfile.parse(spec.wind_profile, option="wind profile")
        wind_label = f"wind speed at {prof.ref_height:g} m [m/s]"
        title += f", {prof.describe()}"
    files["power_curve"] = str(power_curve_plot(records, refs, paths["power_curve"], title, wind_label))
    cells = folding_cells(records)
    mp = folding_map_plot(cells, paths["folding_map"])
    if mp is not None:
        files["folding_map"] = str(mp)
    ans = answer(cells)
    files["summary"] = str(paths["summary"])
    md = summary_markdown(records, ans, spec.scenario, refs, files, (plant_note(spec), wind_note(spec)) + NOTES,
                          n_expected=len(spec.points()))
    atomic_write_text(files["summary"], md)
    return SweepReport(files, ans, answer_sentence(ans, spec.scenario), refs, md, cold_check_differences(records))
