"""Example 1 (Kamman & Nguyen's cable, tow point 35 ft above the water) at
3, 5 and 8 knots, side view: the picture doc/img/equilibrium_speeds_side.png
(doc/plots.md) drawn from Python with matplotlib, a sweep of a scene value.

    python3 examples/python/speeds_side_view.py [OUTDIR]

writes OUTDIR/equilibrium_speeds_side.png and, beside it, the curves drawn
as JSON (speeds_side_view.json: each speed's node positions, m). Run as a
test (test/python/test_example.py), which checks the curves against
`towstab equilibrium --speed V --json`.
"""

import json
import os
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402

import towstab  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "kamman_ex1_above.yaml")
SPEEDS = ["3 knot", "5 knot", "8 knot"]


def main(outdir):
    os.makedirs(outdir, exist_ok=True)
    scene = towstab.Scene.load(SCENE)
    fig, ax = plt.subplots(figsize=(8, 5))
    curves = []
    for speed in SPEEDS:
        # A sweep: a new scene with tow.speed set, as written in a file.
        eq = scene.set("tow.speed", speed).equilibrium()
        T = eq.value("top_tension")
        dT, _ = eq.errors("top_tension")
        label = "%s: top tension %.4g N +- %.1g%s" % (
            speed, T, dT, "" if eq.trustworthy else " (not trustworthy)")
        line, = ax.plot(eq.nodes.x, eq.nodes.z, marker=".", label=label)
        ax.plot(eq.bodies.x, eq.bodies.z, "o", markersize=10,
                color=line.get_color())
        curves.append({"speed": speed, "x": eq.nodes.x.tolist(),
                       "z": eq.nodes.z.tolist(),
                       "trustworthy": eq.trustworthy})
        print(label)
    ax.axhline(0.0, color="tab:blue", linewidth=0.8, linestyle=":")
    ax.text(ax.get_xlim()[0], 0.0, " water surface", va="bottom")
    ax.invert_yaxis()  # z is depth: down is positive
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x [m] (forward of the tow point positive)")
    ax.set_ylabel("z [m] (depth)")
    ax.set_title("kamman_ex1_above: side view at three speeds")
    ax.legend(loc="best", fontsize="small")
    ax.grid(True, alpha=0.3)
    png = os.path.join(outdir, "equilibrium_speeds_side.png")
    fig.savefig(png, dpi=100, bbox_inches="tight")
    with open(os.path.join(outdir, "speeds_side_view.json"), "w") as f:
        json.dump(curves, f)
    print("wrote", png)


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else ".")
