"""Which body of a real pack suffers most, and what a thicker oil film changes: the 8-disc
brake with its 9 separator plates (scenes/pack-8-brake.toml) run as shipped and with the
film of every disc's spline at 75 um (the scene grades it from 75 um at the feed to 0 at
the far end), per body side by side.

    python examples/python/pack_compare.py
"""

import os

import pandas as pd

import clutchpack

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "pack-8-brake.toml")


def peaks(result: clutchpack.Result) -> pd.Series:
    """Largest |per-tooth load| of each body, N."""
    st = result.stats().set_index("name")
    return st[["max_positive_n", "max_negative_n"]].abs().max(axis=1)


def main() -> None:
    # the reference engine runs the whole pack (plates, stack) about ten times faster
    base = clutchpack.run(SCENE, engine="reference", duration=0.1)
    n_discs = sum(1 for b in clutchpack.load_scene(SCENE).bodies if b.startswith("disc"))
    thick = clutchpack.run(
        SCENE,
        engine="reference",
        duration=0.1,
        set={f"discs[{i}].oil.film_thickness_m": 75e-6 for i in range(n_discs)},
    )
    table = pd.DataFrame({"shipped [N]": peaks(base), "75 um film [N]": peaks(thick)})
    table["change [%]"] = 100 * (table.iloc[:, 1] / table.iloc[:, 0] - 1)
    print(table.round(1).to_string())
    worst = table.iloc[:, 0].idxmax()
    print(f"hardest hit as shipped: {worst} ({table.iloc[:, 0].max():.1f} N)")
    life = base.fatigue.set_index("disc")["life_h"]
    print(f"shortest tooth life as shipped: {life.idxmin()} ({life.min():.3g} h)")


if __name__ == "__main__":
    main()
