"""A parameter study: the quarter car's suspension damping against ride comfort and road holding.

The quarter car of examples/quarter_car.toml rests at its static equilibrium when the wheel hits a
bump that throws it upward at 1 m/s. Over 64 suspension dampings d = 300 .. 4000 N s/m
(damping ratios of the body mode zeta = d / (2 sqrt(k_s m_b)) from 0.06 to 0.82) the study
records per case

- the peak body acceleration (comfort: the damper passes the wheel's kick on to the body, so it
  grows with d),
- the suspension travel (peak-to-peak deflection), and
- the body's settling time (after which it stays within 1 mm of rest: the lightest damping
  keeps it moving for about a second).

The two pull in opposite directions: the printout gives both ends and the damping that settles
fastest. The cases run in parallel on every core (``ms.study``), the table is saved to
results/quarter_car_study.h5 and plotted to results/quarter_car_study.png; one case is checked
bit for bit against a direct ``ms.simulate``. As a model file it runs the stiffest-damped case of
the sweep: ``mechsys run examples/quarter_car_study.py``. From the command line:

    mechsys study examples/quarter_car.toml --param force.suspension.d=300:4000:64 \\
        --metric peak=absmax:body/body/acceleration[y] --plot results/damping.png
"""

from pathlib import Path

import numpy as np

import mechsys as ms
from mechsys.modelfile import load_model

HERE = Path(__file__).resolve().parent
G, M_WHEEL, M_BODY, K_TYRE, K_SUSP = 9.81, 40.0, 300.0, 200000.0, 20000.0
BUMP = 1.0  # m/s upward on the wheel
DAMPING = np.linspace(300.0, 4000.0, 64)
# static equilibrium: the tyre carries both masses, the suspension the body
WHEEL_REST = -(M_WHEEL + M_BODY) * G / K_TYRE
BODY_REST = WHEEL_REST - M_BODY * G / K_SUSP

model, _ = load_model(HERE / "quarter_car.toml")
model = model.with_values({"force.suspension.d": float(DAMPING[-1])})
simulation = {"t_end": 3.0, "output_dt": 0.001, "integrator": {"type": "dopri5", "rtol": 1e-9},
              "q0": {"wheel_y": WHEEL_REST, "body_y": BODY_REST}, "u0": {"wheel_y": BUMP}}


def ride(res: ms.Results) -> dict:
    """The metrics of one case (module level, so worker processes can import it)."""
    t, body = res.t, res["joint/body_y/q"]
    away = np.nonzero(np.abs(body - BODY_REST) > 1e-3)[0]
    return {
        "peak_acc": float(np.max(np.abs(res["body/body/acceleration"][:, 1]))),
        "travel": float(np.ptp(res["force/suspension/deflection"])),
        "settling": float(t[away[-1] + 1]) if len(away) and away[-1] + 1 < len(t) else float(t[-1]),
    }


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    st = ms.study(model, {"force.suspension.d": DAMPING}, metrics=ride, settings=simulation,
                  store="results/quarter_car_study.h5")
    print(st)
    assert not st.failed, st.error
    df = st.to_pandas()
    zeta = DAMPING / (2.0 * np.sqrt(K_SUSP * M_BODY))
    best = int(np.argmin(st.metrics["settling"]))
    print(f"ran on {st.attrs['ran_on']} in {st.attrs['wall']:.2f} s")
    for k in (0, best, len(DAMPING) - 1):
        print(f"d = {DAMPING[k]:6.0f} N s/m (zeta = {zeta[k]:.2f}): peak body acceleration "
              f"{st.metrics['peak_acc'][k]:6.3f} m/s^2, travel {st.metrics['travel'][k] * 1e3:5.1f} mm, "
              f"settled after {st.metrics['settling'][k]:.3f} s" + ("  <- settles fastest" if k == best else ""))
    assert np.all(np.diff(st.metrics["peak_acc"]) > 0)  # comfort only gets worse with damping
    # one case again, directly: the same numbers to the last bit
    k = 17
    direct = ms.simulate(model.with_values({"force.suspension.d": float(DAMPING[k])}), progress=False,
                         **{**simulation, "integrator": ms.DOPRI5(rtol=1e-9)})
    again = ride(direct)
    same = all(again[m] == df[m][k] for m in again)
    print(f"case {k} recomputed with ms.simulate: identical = {same}")
    assert same

    fig, axes = plt.subplots(3, 1, figsize=(6.4, 8.0), sharex=True)
    for ax, (name, label) in zip(axes, [("peak_acc", "peak body acceleration (m/s²)"),
                                         ("travel", "suspension travel (m)"), ("settling", "settling time (s)")]):
        st.plot(name, ax=ax)
        ax.set_ylabel(label)
        ax.set_xlabel("")
        ax.set_title("")
    axes[2].axvline(DAMPING[best], color="0.5", ls="--", lw=0.8)
    axes[-1].set_xlabel("suspension damping d (N s/m)")
    fig.suptitle(f"quarter car hitting a bump at {BUMP} m/s: {len(st)} dampings")
    fig.tight_layout()
    Path("results").mkdir(exist_ok=True)
    fig.savefig("results/quarter_car_study.png", dpi=120)
    print("wrote results/quarter_car_study.h5 and results/quarter_car_study.png")


if __name__ == "__main__":
    main()
