"""Compare a `tubemem run` folder with the independent references.

    python -m tubemem_ref.compare RUN_DIR [--out RUN_DIR/compare]
    python python_ref/compare.py RUN_DIR [--out RUN_DIR/compare]     (in the checkout)

`tubemem verify` imports this module from the package installed in its Python
(`pip install ./python_ref`), or from the `python_ref` folder it finds (`--python-ref`,
`TUBEMEM_PYTHON_REF`, or the checkout above the case or the working folder).

For every stage of the run it computes the matching reference and prints (and writes as
compare.csv) a side-by-side table of the mid-span values: FE (Rust), scikit-fem, closed form,
and the relative differences.
- inflation stage: the scikit-fem axisymmetric capped tube of the same L/R at the FE's mid-span
  λs, and GPS (eq. 66); it also plots the end-cap profile λs(Z), FE against axisymmetric, as
  profile_stageN.png and reports the largest difference along the tube; an arc-length stage's
  located pressure maximum (polygon factor taken out) against the axisymmetric tube's maximum
  and the GPS limit point (limit_max_w, limit_max_lambda_s);
- squeeze stage: the scikit-fem GPS cross-section with contact at the FE's λs* and ρ, and GPS
  flattening (eqs. 76-77);
- confine stage: the scikit-fem periodic GPS ring (gps_ring, any planes) with the gas closed in
  at the FE's λs* and the stage's planes moved from their offsets to their targets, and the
  Rust closed form of summary.json (`gps`): ϖ, λs, λz and each wall's force.
The law is read from summary.json's material_spec: Anssari-Benam--Bucchi, Mooney--Rivlin or
neo-Hookean, in every reference.
"""

import argparse
import csv
import pathlib

import numpy as np

from tubemem_ref import axisym, closed_form, gps_section, runs


def rel(a, b):
    return a / b - 1.0


def read_profile(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: np.array([float(r[k]) for r in rows]) for k in rows[0]}


def compare(run_dir, out_dir, plot=True):
    run_dir = pathlib.Path(run_dir)
    out_dir = pathlib.Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    summary = runs.read_summary(run_dir)
    spec, geo = summary["material_spec"], summary["geometry"]
    try:
        law = closed_form.law_of_spec(spec)
    except ValueError as e:
        raise SystemExit(f"{run_dir / 'summary.json'}: {e}")
    if geo.get("caps") != "hemisphere":
        raise SystemExit("the axisymmetric reference models hemispherical caps only")
    length = geo["length"] / geo["radius"]
    print(f"law: {law[0]} {law[1]:g} (from summary.json)")
    rows = []
    ls_star = None
    for st in summary["stages"]:
        if "final" not in st:
            continue
        fin, idx = st["final"], st["index"]
        if st["kind"] == "inflate":
            # an arc-length stage's located pressure maximum against the axisymmetric tube's
            # (same L/R and law; golden section on the stretch-controlled path) and GPS's: the FE
            # value with the mesh's polygon factor 1/cos(pi/n) taken out
            for c in st.get("critical_points", []):
                if c["kind"] != "limit-max" or c.get("ripple") or "polygon_factor" not in c:
                    continue
                gps_max = closed_form.gps_pressure_maximum(law=law)
                if gps_max is None:
                    continue
                ls_g, w_g, _ = gps_max
                ls_ax, w_ax = axisym.pressure_maximum(length, ls_g - 0.05, ls_g + 0.1, law=law,
                                                      cylinder_elements=int(8 * length))
                fe_w = c["w"] / c["polygon_factor"]
                rows.append((idx, "inflate", "limit_max_w", fe_w, w_ax, w_g, rel(fe_w, w_ax), rel(fe_w, w_g), rel(w_ax, w_g)))
                rows.append((idx, "inflate", "limit_max_lambda_s", c["lambda_s"], ls_ax, ls_g,
                             rel(c["lambda_s"], ls_ax), rel(c["lambda_s"], ls_g), rel(ls_ax, ls_g)))
            ls = fin["lambda_s"]
            try:
                tube, q, p = axisym.inflate_to(length, ls, law=law, cylinder_elements=int(8 * length))
            except RuntimeError as e:
                # past the pressure maximum the mid-span stretch plateaus while a bulge
                # propagates: the stretch-controlled reference cannot follow such a path
                print(f"stage {idx}: no axisymmetric reference ({e}); bulge inflations are not replicated")
                continue
            ax = tube.midspan(q, p)
            w, lz = closed_form.gps_inflation(ls, law=law)
            for k, fe, sk, cf in [("w", fin["w"], ax["w"], w), ("lambda_z", fin["lambda_z"], ax["lambda_z"], lz)]:
                rows.append((idx, "inflate", k, fe, sk, cf, rel(fe, sk), rel(fe, cf), rel(sk, cf)))
            # summary.json names the profile relative to the run folder
            prof = read_profile(pathlib.Path(run_dir) / st["profile"])
            z_ax, ls_ax, lz_ax, s_ax = tube.profile(q)
            cyl = s_ax >= np.pi / 2 - 1e-12
            z_ref_ax = length / 2 - (s_ax[cyl] - np.pi / 2)
            order = np.argsort(z_ref_ax)
            sel = prof["z_ref"] >= -1e-12
            ls_interp = np.interp(prof["z_ref"][sel], z_ref_ax[order], ls_ax[cyl][order])
            diff = prof["lambda_s"][sel] - ls_interp
            imax = int(np.argmax(np.abs(diff)))
            rows.append((idx, "inflate", "profile max |Δλs|", float(np.abs(diff).max()), float(prof["z_ref"][sel][imax]),
                         np.nan, np.nan, np.nan, np.nan))
            # λz(Z): the axisymmetric meridian stretch (finite differences at the P2 vertices)
            # against the FE's mean meridian edge stretch at each ring; both are O(h) at the
            # cap junction, where the meridian curvature jumps
            lz_interp = np.interp(prof["z_ref"][sel], z_ref_ax[order], lz_ax[cyl][order])
            dlz = prof["lambda_z"][sel] - lz_interp
            jmax = int(np.argmax(np.abs(dlz)))
            rows.append((idx, "inflate", "profile max |Δλz|", float(np.abs(dlz).max()), float(prof["z_ref"][sel][jmax]),
                         np.nan, np.nan, np.nan, np.nan))
            if plot:
                import matplotlib
                matplotlib.use("Agg")
                import matplotlib.pyplot as plt
                fig, ax1 = plt.subplots(figsize=(8, 5))
                ax1.plot(z_ref_ax[order], ls_ax[cyl][order], "-", label="scikit-fem axisymmetric")
                ax1.plot(prof["z_ref"][sel], prof["lambda_s"][sel], "o", ms=3, label="tubemem FE (Rust)")
                ax1.axhline(ls, color="grey", ls=":", label="mid-span λs")
                ax1.set_xlabel("reference height Z/R (0 = mid-span, L/2R = cap junction)")
                ax1.set_ylabel("hoop stretch λs")
                ax1.set_title(f"End-cap profile, stage {idx}, L/R = {length:g}")
                ax1.legend()
                fig.tight_layout()
                fig.savefig(out_dir / f"profile_stage{idx}.png", dpi=110)
                plt.close(fig)
            ls_star = ls
        elif st["kind"] == "confine":
            from tubemem_ref import gps_ring
            ls0 = ls_star if ls_star is not None else fin["lambda_s"]
            planes = st["planes"]

            def walls(t):
                # tubemem's n.x <= d as python_ref's (nx, ny, d) with nx x + ny y >= d
                out = []
                for p in planes:
                    n = np.hypot(*p["normal"])
                    d = p["offset"] + t * (p["target"] - p["offset"])
                    out.append((-p["normal"][0] / n, -p["normal"][1] / n, -d / n))
                return out

            # the rigid modes: all pinned until every wall touches (a wall alone pushes the free
            # ring away), then only those the walls cannot hold: the rotation, and a translation
            # along which the plane set is symmetric (its multiplier then carries no load)
            def symmetric(axis):
                ws = walls(1.0)
                flip = [(-a, b, d) if axis == 0 else (a, -b, d) for a, b, d in ws]
                return all(any(np.allclose(f, w, atol=1e-12) for w in ws) for f in flip)

            pins = tuple(k for k in (0, 1) if symmetric(k)) + (2,)
            held = gps_ring.GpsRing(elements=128, penalty=1e5, rigid=(0, 1, 2), law=law)
            ring = gps_ring.GpsRing(elements=128, penalty=1e5, rigid=pins, law=law)
            w0, lz0 = closed_form.gps_inflation(ls0, law=law)
            m = w0 * lz0 * np.pi * ls0**2
            q, lz = held.circle(ls0), lz0
            t_all = max(0.0, max((p["offset"] - ls0 * np.hypot(*p["normal"])) / (p["offset"] - p["target"])
                                 for p in planes if p["offset"] != p["target"]))
            for t in np.linspace(0.0, 1.0, 101)[1:]:
                q, lz, _ = (held if t <= t_all + 0.02 else ring).solve(q, lz, walls(t), m)
            o = ring.outputs(q, lz, walls(1.0), m)
            cf = st["gps"]
            for k in ["w", "lambda_s", "lambda_z"]:
                rows.append((idx, "confine", k, fin[k], o[k], cf[k], rel(fin[k], o[k]), rel(fin[k], cf[k]), rel(o[k], cf[k])))
            for j, wall in enumerate(st["walls"]):
                fe, sk, c = wall["fe"]["force"], o["forces"][j], cf["walls"][j]["force"]
                rows.append((idx, "confine", f"force wall {j + 1}", fe, sk, c, rel(fe, sk), rel(fe, c), rel(sk, c)))
        elif st["kind"] == "squeeze":
            ls0, rho = fin["initial_stretch"], fin["rho"]
            sec = gps_section.squeeze(ls0, [rho], elements=64, penalty=1e5, law=law)[0]
            cf = closed_form.gps_flattening(ls0, [rho], law=law)[0]
            for k in ["w", "lambda_s", "lambda_z", "chi", "force"]:
                rows.append((idx, "squeeze", k, fin[k], sec[k], cf[k], rel(fin[k], sec[k]), rel(fin[k], cf[k]), rel(sec[k], cf[k])))
    header = ["stage", "kind", "quantity", "fe", "scikit_fem", "closed_form", "fe_vs_skfem", "fe_vs_closed", "skfem_vs_closed"]
    with open(out_dir / "compare.csv", "w", newline="") as f:
        wr = csv.writer(f)
        wr.writerow(header)
        wr.writerows(rows)
    print(f"{'stage':>5} {'kind':>8} {'quantity':>18} {'FE':>12} {'scikit-fem':>12} {'closed':>12} {'FE/skfem-1':>11} {'FE/GPS-1':>10} {'skfem/GPS-1':>11}")
    for r in rows:
        if r[2].startswith("profile"):
            print(f"{r[0]:>5} {r[1]:>8} {r[2]:>18} {r[3]:>12.3e} at Z = {r[4]:.3f}")
        else:
            print(f"{r[0]:>5} {r[1]:>8} {r[2]:>18} {r[3]:>12.7f} {r[4]:>12.7f} {r[5]:>12.7f} {r[6]:>+11.2e} {r[7]:>+10.2e} {r[8]:>+11.2e}")
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser(description="Compare a tubemem run folder with the scikit-fem references and the closed form.")
    ap.add_argument("run_dir")
    ap.add_argument("--out", default=None)
    ap.add_argument("--no-plot", action="store_true")
    a = ap.parse_args(argv)
    compare(a.run_dir, a.out or pathlib.Path(a.run_dir) / "compare", plot=not a.no_plot)


if __name__ == "__main__":
    main()
