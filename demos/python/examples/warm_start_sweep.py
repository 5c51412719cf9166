"""A parameter study without C++: the stack's drift over 10 s for warm-start factors 0 to 1.

Each run steps the paper's stack (5 cubes dropped in a column) with one warm-start factor and
measures how far the column's top cube has moved sideways from where it started (m) at the end;
the plot shows drift against the factor. Usage: python3 warm_start_sweep.py [OUT.png] [SECONDS]
(default warm_start_sweep.png, 10 s). Prints one line per factor.
"""
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt
import numpy as np

import cps


def drift(warm_start, seconds):
    """The top cube's horizontal distance (m) from its start after `seconds` s."""
    run = cps.Run("stack", warm_start=warm_start)
    start = run.state()["positions"]
    top = int(np.argmax(start[:, 1]))
    run.advance_to(seconds)
    moved = run.state()["positions"][top] - start[top]
    return float(np.hypot(moved[0], moved[2]))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "warm_start_sweep.png"
    seconds = float(sys.argv[2]) if len(sys.argv) > 2 else 10.0
    factors = np.linspace(0.0, 1.0, 6)
    drifts = [drift(f, seconds) for f in factors]
    for f, d in zip(factors, drifts):
        print(f"warm_start {f:.1f}: top cube drift {d:.4f} m after {seconds:g} s")
    fig, ax = plt.subplots(figsize=(5, 3.2), dpi=100)
    ax.plot(factors, drifts, "o-")
    ax.set_xlabel("warm-start factor")
    ax.set_ylabel(f"top cube drift after {seconds:g} s (m)")
    ax.set_title("stack: drift against warm starting")
    fig.tight_layout()
    fig.savefig(out)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()
