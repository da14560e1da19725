"""The paper's Fig 3 with ensembles: the largest per-tooth impact loads against the oil film
thickness h_o, each thickness an ensemble of discs started across the free play (the rattle is
chaotic: a mean and a spread, not one sample), with a quadratic fit of the means.

    python examples/python/fig3.py                  # the table
    python examples/python/fig3.py --json fig3.json # also the sweep's summary as JSON
    python examples/python/fig3.py --plot fig3.png  # and a figure (needs matplotlib)

The same numbers as `clutchpack sweep scenes/hu-table2.toml --param
defaults.oil.film_thickness_m --values 0,25e-6,50e-6,75e-6,100e-6 --ensemble 16`.
"""

import argparse
import json
import os

import numpy as np

import clutchpack

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "..", "scenes", "hu-table2.toml")
PARAM = "defaults.oil.film_thickness_m"
VALUES = [0.0, 25e-6, 50e-6, 75e-6, 100e-6]  # m


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ensemble", type=int, default=16, help="members per thickness")
    ap.add_argument("--json", help="write the sweep's summary (rows, fatigue) here")
    ap.add_argument("--plot", help="write the figure here (PNG or SVG; needs matplotlib)")
    a = ap.parse_args()

    s = clutchpack.sweep(SCENE, PARAM, VALUES, ensemble=a.ensemble)
    rows = s.rows
    print(f"{'h_o [um]':>9} {'max + mean [N]':>15} {'std':>7} {'max - mean [N]':>15} {'std':>7}")
    for _, r in rows.iterrows():
        print(
            f"{r['value'] * 1e6:9.0f} {r['max_positive_mean']:15.1f} {r['max_positive_std']:7.1f}"
            f" {r['max_negative_mean']:15.1f} {r['max_negative_std']:7.1f}"
        )
    x = rows["value"].to_numpy() * 1e6
    fit = np.polyfit(x, rows["max_positive_mean"].to_numpy(), 2)
    print("max + mean = {:.1f} {:+.3f} h {:+.5f} h^2 (h in um)".format(fit[2], fit[1], fit[0]))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(s.summary, f, indent=1)
    if a.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(6, 4))
        for stat, label in (("max_positive", "max +"), ("max_negative", "max -")):
            ax.errorbar(x, rows[f"{stat}_mean"], yerr=rows[f"{stat}_std"], fmt="o", label=label)
        ax.set_xlabel("oil film thickness h_o [um]")
        ax.set_ylabel("per-tooth impact load [N]")
        ax.legend()
        fig.savefig(a.plot, dpi=120, bbox_inches="tight")


if __name__ == "__main__":
    main()
