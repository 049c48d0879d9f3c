#!/usr/bin/python3
"""Draws one drag trace like the figures of Lloyd & Pai 2001, and the map, to a PNG.

    plot_trace.py --server ADDR (--trace ID | --job ID) -o trace.png
    plot_trace.py [--scene bottle] -o trace.png     # starts surfmapd + rigs, maps the scene, picks a trace

Panels:
  (a) the contact force in the drag's own frame (surfmap_client.drag_frame:
      normal force; force along the drag, which is friction, and lateral
      force) along the path, forward and reverse pass, data window shaded
      (the window is the server's fit: window_start_mm..window_end_mm). Not
      world fx/fz: on a drag along y or down a wall those hide the friction;
  (b) per-point mu along the window (the server's own per-pair values,
      GetSample with include_series), with the server's mu and std;
  (c) the autocorrelation of the force variation: measured (the server's, on
      its grid) against the ACF implied by the server's AR coefficients;
  (d) measured force variation against a resynthesised AR process with the
      server's coefficients and sigma (seeded);
  (e, f) the map (per-vertex mu, grey: whiter = more friction) seen from the
      two sides of its thinnest axis, sample sites and drag segments drawn,
      this trace's site circled.

With --job, the trace is the job's sample with the largest roughness sigma
(the most texture to look at) among those with mu_std <= 0.05 (drags over
one material, not across a boundary), unless --trace is given.
"""

from __future__ import annotations

import argparse
import sys
from typing import List, Optional

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import surfmap_client as sc  # noqa: E402
from surfmap_client import trace_analysis as ta  # noqa: E402
from surfmap_client.drag_frame import drag_frame_forces  # noqa: E402

from example_lab import add_lab_arguments, measure, open_lab, scenes_dir  # noqa: E402

RESYNTHESIS_SEED = 2001
UNIFORM_MU_STD = 0.05  # a drag over one material (sandpaper: ~0.03; across a glass/sandpaper boundary: ~0.15)


def parse_args(argv: List[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    add_lab_arguments(parser)
    parser.add_argument("--trace", type=int, help="trace id to draw")
    parser.add_argument("--job", type=int, help="job whose map to draw (and whose roughest sample, without --trace)")
    parser.add_argument("--scene", default="bottle", help="scene to map when no --job/--trace is given")
    parser.add_argument("--finest", type=int, default=1, help="finest level of that job")
    parser.add_argument("--step-mm", type=float, default=0.1, help="arc-length grid of the roughness analysis")
    parser.add_argument("-o", "--output", required=True, help="PNG file to write")
    return parser.parse_args(argv)


def choose_sample(client: sc.SurfmapClient, args: argparse.Namespace) -> sc.Sample:
    if args.trace:
        return client.get_sample(args.trace, include_series=True)
    samples = [s for s in client.list_samples(args.job) if s.fit is not None]
    if not samples:
        raise RuntimeError(f"job {args.job} has no fitted samples yet")
    # A drag across a material boundary has a large sigma too (the step in
    # friction looks like texture), so prefer drags whose mu is uniform.
    fits = [(s, s.fit) for s in samples if s.fit is not None]
    uniform = [(s, f) for s, f in fits if f.friction.mu_std <= UNIFORM_MU_STD] or fits
    chosen, _ = max(uniform, key=lambda pair: pair[1].roughness.sigma)
    return client.get_sample(chosen.trace_id, include_series=True)


def draw_forces(axes, trace: sc.Trace, fit: sc.Fit) -> None:
    """(a): normal force above; force along the drag (friction) and lateral force below."""
    framed = drag_frame_forces(trace, fit.friction.normal)
    window = (fit.friction.window_start_mm, fit.friction.window_end_mm)
    normal_ax, tangent_ax = axes
    for mask, style, label in ((trace.forward, "-", "forward"), (trace.reverse, "--", "reverse")):
        order = np.argsort(framed.s[mask], kind="stable")
        s = framed.s[mask][order]
        normal_ax.plot(s, framed.normal[mask][order], style, color="tab:blue", lw=0.8, label=f"normal, {label}")
        tangent_ax.plot(s, framed.along[mask][order], style, color="tab:red", lw=0.8, label=f"along the drag, {label}")
        tangent_ax.plot(s, framed.lateral[mask][order], style, color="0.5", lw=0.6, label=f"lateral, {label}")
    for ax in axes:
        ax.axvspan(*window, color="0.9", zorder=0, label="data window (server)")
    tangent_ax.axhline(0, color="0.5", lw=0.5)
    seen_mu = framed.window_friction(trace, *window)
    normal_ax.set_ylabel("normal force, N")
    normal_ax.set_title(f"(a) contact force in the drag frame (normal from {framed.normal_source}): "
                        f"forward and reverse pass")
    normal_ax.legend(fontsize=7, ncol=3, loc="lower center")
    tangent_ax.set_ylabel("tangential force, N")
    tangent_ax.set_xlabel("position along the forward path, mm")
    tangent_ax.set_title(f"along the drag (forward ~ -mu N, reverse ~ +mu N; in the window they give "
                         f"mu {seen_mu:.4f}) and lateral", fontsize=10)
    tangent_ax.legend(fontsize=7, ncol=5, loc="upper center", bbox_to_anchor=(0.5, -0.22))


def draw_point_mu(ax, fit: sc.Fit) -> None:
    window = (fit.friction.window_start_mm, fit.friction.window_end_mm)
    mu, std = fit.friction.mu, fit.friction.mu_std
    ax.plot(fit.friction.pair_s_mm, fit.friction.pair_mu, ".", ms=3, color="k", label="per pair (server)")
    ax.axhline(mu, color="tab:red", label=f"server fit mu = {mu:.4f}")
    ax.axhspan(mu - std, mu + std, color="tab:red", alpha=0.15, label=f"server std {std:.4f}")
    ax.set_xlim(*window)
    ax.set_xlabel("position along the forward path, mm")
    ax.set_ylabel("mu = tan(theta / 2)")
    ax.set_title("(b) friction per point along the window")
    ax.legend(fontsize=7, loc="best")


def draw_acf(ax, fit: sc.Fit) -> None:
    step_mm = fit.roughness.grid_step_mm
    max_lag = min(60, fit.roughness.acf.size - 1)
    lags = np.arange(max_lag + 1) * step_mm
    measured = fit.roughness.acf[:max_lag + 1]
    ax.plot(lags, measured, "o-", ms=2, lw=0.8, color="k", label="measured (server)")
    coefficients = fit.roughness.ar_coefficients
    if coefficients and fit.roughness.stationary:
        model = ta.ar_model_autocorrelation(coefficients, max_lag)
        ax.plot(lags, model, "-", color="tab:red",
                label="AR model (server: " + ", ".join(f"a{i + 1}={a:.2f}" for i, a in enumerate(coefficients)) + ")")
    if fit.roughness.acf_decay_mm > 0:
        ax.axvline(fit.roughness.acf_decay_mm, color="tab:red", ls=":",
                   label=f"server ACF decay {fit.roughness.acf_decay_mm:.2f} mm")
    ax.axhline(0, color="0.5", lw=0.5)
    ax.set_xlabel("lag, mm")
    ax.set_ylabel("autocorrelation")
    ax.set_title("(c) autocorrelation of the force variation")
    ax.legend(fontsize=7, loc="best")


def draw_roughness(ax, passes, fit: sc.Fit) -> None:
    grid, measured = passes[0]
    ax.plot(grid, measured, lw=0.8, color="k", label="measured, forward pass (|f_t| - mu f_n, detrended)")
    r = fit.roughness
    if r.ar_coefficients and r.stationary:
        synthetic = ta.synthesize_ar(r.ar_coefficients, r.sigma, len(grid), seed=RESYNTHESIS_SEED)
        ax.plot(grid, synthetic, lw=0.8, color="tab:red", alpha=0.8,
                label=f"resynthesised AR({len(r.ar_coefficients)}), sigma {r.sigma:.3f} N (seed {RESYNTHESIS_SEED})")
    note = " (server: below the sensor noise floor)" if r.below_noise_floor else ""
    ax.set_xlabel("position along the forward path, mm")
    ax.set_ylabel("force variation, N")
    ax.set_title("(d) roughness: measured vs resynthesised" + note)
    ax.legend(fontsize=7, loc="best")


def draw_map(axes, surface: sc.SurfaceMap, highlight: Optional[sc.Sample]) -> None:
    positions, triangles = surface.positions, surface.triangles
    if positions is None or triangles is None:
        raise RuntimeError(f"the map of job {surface.job_id} came without its mesh")
    centred = positions - positions.mean(axis=0)
    # Principal axes: the longest is drawn upright, the thinnest is the view direction.
    _, _, axes_t = np.linalg.svd(centred, full_matrices=False)
    up, across, view = axes_t[0], axes_t[1], axes_t[2]
    face_normals = np.cross(positions[triangles[:, 1]] - positions[triangles[:, 0]],
                            positions[triangles[:, 2]] - positions[triangles[:, 0]])
    facing = face_normals @ view
    if (facing > 0).sum() < (facing < 0).sum():
        view, across, facing = -view, -across, -facing  # "front" is the side most faces look at
    mu = np.where(np.isfinite(surface.mu), surface.mu, np.nan)
    vmin, vmax = np.nanmin(mu), np.nanmax(mu)
    image = None
    for ax, sign, title in ((axes[0], 1.0, "(e) map, front"), (axes[1], -1.0, "(f) map, back")):
        shown = triangles[sign * facing > 0]
        x = sign * (positions @ across)
        y = positions @ up
        ax.set_title(title)
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        if len(shown) == 0:
            ax.text(0.5, 0.5, "no surface faces this way", ha="center", va="center", transform=ax.transAxes)
            continue
        image = ax.tripcolor(x, y, shown, mu, shading="gouraud", cmap="gray", vmin=vmin, vmax=vmax)
        for s in surface.samples:
            normal = s.fit.friction.normal if s.fit is not None else view
            if sign * float(np.dot(normal, view)) <= 0:
                continue
            half = 0.5 * s.segment_length_mm * s.drag_direction
            ends = np.array([s.position - half, s.position + half])
            ax.plot(sign * (ends @ across), ends @ up, color="tab:orange", lw=0.8)
            ax.plot(sign * (s.position @ across), s.position @ up, ".", color="tab:red", ms=2.5)
        if highlight is not None and highlight.fit is not None \
                and sign * float(np.dot(highlight.fit.friction.normal, view)) > 0:
            ax.plot(sign * (highlight.position @ across), highlight.position @ up, "o", mfc="none",
                    mec="tab:cyan", ms=12, mew=2, label=f"trace {highlight.trace_id}")
            ax.legend(fontsize=7, loc="lower right")
    if image is not None:
        colorbar = plt.colorbar(image, ax=list(axes), shrink=0.8)
        colorbar.set_label("mu (whiter = more friction)")


def plot(client: sc.SurfmapClient, args: argparse.Namespace) -> str:
    sample = choose_sample(client, args)
    if sample.fit is None:
        raise RuntimeError(f"trace {sample.trace_id} has no fit")
    fit = sample.fit
    trace = client.get_trace(sample.trace_id)
    surface = client.get_map(sample.job_id)
    window = (fit.friction.window_start_mm, fit.friction.window_end_mm)
    passes = ta.force_variation(trace, fit.friction.mu, window, args.step_mm)

    figure = plt.figure(figsize=(13, 20), dpi=100, layout="constrained")
    grid = figure.add_gridspec(5, 2, height_ratios=[0.8, 0.9, 1, 1, 1.6])
    normal_ax = figure.add_subplot(grid[0, :])
    draw_forces([normal_ax, figure.add_subplot(grid[1, :], sharex=normal_ax)], trace, fit)
    draw_point_mu(figure.add_subplot(grid[2, 0]), fit)
    draw_acf(figure.add_subplot(grid[2, 1]), fit)
    draw_roughness(figure.add_subplot(grid[3, :]), passes, fit)
    draw_map([figure.add_subplot(grid[4, 0]), figure.add_subplot(grid[4, 1])], surface, sample)
    figure.suptitle(f"trace {sample.trace_id} (job {sample.job_id}, site L{sample.level}/v{sample.vertex}): "
                    f"mu {fit.friction.mu:.4f} +- {fit.friction.mu_std:.4f}, {fit.friction.pair_count} pairs, "
                    f"fit v{fit.version} {fit.estimator}", fontsize=11)
    figure.savefig(args.output)
    plt.close(figure)
    return (f"wrote {args.output}: trace {sample.trace_id} of job {sample.job_id}, mu {fit.friction.mu:.4f}, "
            f"sigma {fit.roughness.sigma:.4f} N, map level {surface.level} with {len(surface.samples)} samples")


def main(argv: List[str]) -> int:
    args = parse_args(argv)
    try:
        with open_lab(args) as client:
            if not args.trace and not args.job:
                if args.server:
                    print("plot_trace: with --server, give --trace or --job", file=sys.stderr)
                    return 2
                obj = client.upload_object(scenes_dir(args) / f"{args.scene}.obj", name=args.scene)
                job = client.create_job(obj.object_id, sc.Property.BOTH, sc.SamplingMode.ADAPTIVE,
                                        finest_level=args.finest, threshold=2.0, seed=2001)
                measure(client, args, args.scene, job.job_id)
                args.job = job.job_id
            print(plot(client, args))
        return 0
    except (sc.SurfmapError, RuntimeError, ValueError, OSError) as error:
        print(f"plot_trace: {error}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
