#!/usr/bin/python3
"""Tessera against VTK 9.1's volume mappers, in one alternating run.

Renders the same picture with `tessera render` (GPU ray caster through EGL),
vtkGPUVolumeRayCastMapper (OpenGL, here on the same Mesa llvmpipe through
Xvfb/GLX) and vtkFixedPointVolumeRayCastMapper (CPU, multi-threaded): same
volume, orientation, camera, image size, transfer function, sample distance and
shading. Rounds alternate the three renderers so that the load of a shared
machine falls on all of them alike; only ratios measured in one run count.

Per configuration it reports the PSNR of Tessera's frame at azimuth 0 against
each VTK mapper's (the proof that they draw the same picture), the median
frame time of each renderer and Tessera's speed-up over each mapper, as a
Markdown table on stdout, and peers.md, peers.json, peers.csv and peers.png in
--out. See bench/peers/README.md.

Run with the system Python (python3-vtk9, numpy, nibabel):
    /usr/bin/python3 bench/peers/peers.py            # re-executes itself under xvfb-run
    /usr/bin/python3 bench/peers/peers.py --smoke    # seconds: a tiny case, checks the matching
"""

import argparse
import csv
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
DEFAULT_VOLUME = "/usr/share/mricron/templates/ch2.nii.gz"
XVFB_SCREEN = "-screen 0 1280x1024x24"
RENDERERS = ("tessera", "vtk-cpu", "vtk-gpu")


# --------------------------------------------------------------------------
# The volume, as Tessera sees it


class PatientVolume:
    """A NIfTI volume in RAS+ storage order, with what Tessera derives from it:
    the value range (its default value window), spacing, extent = dims *
    spacing (the box Tessera renders, voxel centres half a voxel inside) and
    the nearest rotation of the direction cosines (Camera::frame)."""

    def __init__(self, path):
        import nibabel as nib

        # Tessera keeps the storage order and puts the orientation in the
        # camera (modelFromWorld); VTK's vtkImageData is axis-aligned and its
        # camera cannot be mirrored, so reorder the voxels to RAS here (a
        # permutation and flips: the same world positions, Tessera's picture).
        img = nib.as_closest_canonical(nib.load(path))
        # The array proxy applies scl_slope/scl_inter, as Tessera's reader
        # does, and keeps the stored type when there is nothing to apply.
        data = np.asanyarray(img.dataobj)
        if data.dtype.kind == "f" and data.dtype != np.float32:
            data = data.astype(np.float32)
        if data.ndim == 4 and data.shape[3] == 1:
            data = data[..., 0]
        if data.ndim != 3:
            raise SystemExit(f"{path}: expected a 3-D volume, got shape {data.shape}")
        if data.dtype == np.int8:
            data = data.astype(np.int16)  # as Tessera's reader (i8 -> i16)
        self.path = path
        self.data = data
        self.dims = np.array(data.shape, dtype=int)
        affine = img.affine
        self.spacing = np.linalg.norm(affine[:3, :3], axis=0)
        u, _, vt = np.linalg.svd(affine[:3, :3] / self.spacing)
        self.direction = u @ vt  # nearest orthonormal; a proper rotation after canonical
        self.value_min = float(data.min())
        self.value_max = float(data.max())
        if self.value_max <= self.value_min:
            self.value_max = self.value_min + 1.0
        self.extent = self.dims * self.spacing

    def sample_distance(self, step_voxels):
        """Tessera's --step is in voxels of the smallest spacing."""
        return step_voxels * float(self.spacing.min())

    def raw(self, x):
        """Raw value at normalised value x (Tessera's TF axis)."""
        return self.value_min + x * (self.value_max - self.value_min)


# --------------------------------------------------------------------------
# The camera, as Tessera's Camera (include/tessera/core/Camera.h)


def tessera_camera(volume, azimuth_deg, elevation_deg=0.0, fov_deg=30.0, zoom=1.0):
    """Eye, focal point and view-up in VTK's frame (voxel index * spacing,
    origin 0) for Tessera's orbit camera: azimuth 0 looks at the face from
    anterior, up is superior, distance = radius / sin(fov / 2) / zoom with
    radius half the diagonal of dims * spacing."""
    az, el = math.radians(azimuth_deg), math.radians(elevation_deg)
    back = np.array([math.sin(az) * math.cos(el), math.cos(az) * math.cos(el), math.sin(el)])
    right = np.array([-math.cos(az), math.sin(az), 0.0])
    up = np.cross(back, right)
    model_from_world = volume.direction.T
    back, up = model_from_world @ back, model_from_world @ up
    radius = 0.5 * float(np.linalg.norm(volume.extent))
    distance = radius / math.sin(0.5 * math.radians(fov_deg)) / zoom
    # Voxel centres run from 0 to (dims - 1) * spacing in VTK; the centre of
    # Tessera's box is the centre of those.
    centre = 0.5 * (volume.dims - 1) * volume.spacing
    return centre + back * distance, centre, up


# --------------------------------------------------------------------------
# Tessera


class Tessera:
    def __init__(self, binary, volume_path, tf, extra_args):
        self.binary = binary
        self.volume_path = volume_path
        self.tf = tf
        self.extra = extra_args
        help_text = subprocess.run(
            [binary, "render", "--help"], capture_output=True, text=True, check=True
        ).stdout
        self.has_shade = "--shade" in help_text

    def transfer_function(self):
        out = subprocess.run(
            [self.binary, "bench", "--tf", self.tf, "--print-tf"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout
        return json.loads(out)

    def frames(self, cfg, first_azimuth, count, png, variant_args=()):
        """Renders `count` frames rotating from first_azimuth; returns the
        per-frame milliseconds Tessera measured (render + glFinish, after
        shader compile and upload, no PNG writing) and its JSON report.
        `variant_args`: the ablation's sampling options (docs/sampling.md)."""
        cmd = [
            self.binary, "render", self.volume_path,
            "--tf", self.tf,
            "--size", f"{cfg['width']}x{cfg['height']}",
            "--step", str(cfg["step"]),
            "--azimuth", str(first_azimuth),
            "--repeat", str(count),
            "--rotate", str(cfg["rotate"]),
            "--json", "--out", png,
        ] + (["--shade"] if cfg["shade"] else []) + self.extra + list(variant_args)
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"tessera failed: {' '.join(cmd)}\n{run.stderr}")
        report = json.loads(run.stdout)
        return [float(ms) for ms in report["frame_ms"]], report

    def fine_reference(self, cfg, fine_step, png):
        """Tessera's CPU reference at azimuth 0 with every sample at
        `fine_step` voxels, post-classified (--reference-step): what each
        Tessera image is judged against. Untimed."""
        ref_png = png.replace(".png", "-fine.png")
        cmd = [
            self.binary, "render", self.volume_path,
            "--tf", self.tf,
            "--size", f"{cfg['width']}x{cfg['height']}",
            "--step", str(cfg["step"]),
            "--reference-step", str(fine_step), "--reference-out", ref_png,
            "--json", "--out", png,
        ] + (["--shade"] if cfg["shade"] else []) + self.extra
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            raise SystemExit(f"tessera failed: {' '.join(cmd)}\n{run.stderr}")
        return read_png_rgb(ref_png), json.loads(run.stdout)


# --------------------------------------------------------------------------
# VTK


class VtkRenderer:
    """One VTK mapper in its own off-screen window, set up like Tessera. One
    window per mapper for the whole run, reconfigured per configuration: a
    fresh window per configuration made the fixed-point mapper draw the
    fourth one at a square aspect (a stretched head, 19 dB) and a bare
    sequence of fresh windows lost the X connection."""

    def __init__(self, kind, volume, image_data, tf, lighting):
        import vtk

        self.vtk = vtk
        self.volume = volume
        self.kind = kind

        colour = vtk.vtkColorTransferFunction()
        colour.SetColorSpaceToRGB()  # Tessera interpolates RGB linearly
        for p in tf["color"]:
            colour.AddRGBPoint(volume.raw(p["x"]), *p["rgb"])
        colour.SetClamping(True)  # outside the first/last point the end value holds
        opacity = vtk.vtkPiecewiseFunction()
        for p in tf["opacity"]:
            opacity.AddPoint(volume.raw(p["x"]), p["alpha"])
        opacity.SetClamping(True)

        prop = vtk.vtkVolumeProperty()
        prop.SetColor(colour)
        prop.SetScalarOpacity(opacity)
        # Both define opacity per unit world length and correct it for the
        # sample distance as a = 1 - (1 - a0)^(ds / unit).
        prop.SetScalarOpacityUnitDistance(tf.get("opacity_unit_length", 1.0))
        prop.SetInterpolationTypeToLinear()
        prop.SetIndependentComponents(True)
        prop.SetAmbient(lighting["ambient"])
        prop.SetDiffuse(lighting["diffuse"])
        prop.SetSpecular(lighting["specular"])
        prop.SetSpecularPower(lighting["shininess"])

        if kind == "vtk-gpu":
            mapper = vtk.vtkGPUVolumeRayCastMapper()
            mapper.SetUseJittering(False)
        else:
            mapper = vtk.vtkFixedPointVolumeRayCastMapper()
            mapper.SetMinimumImageSampleDistance(1.0)
            mapper.SetMaximumImageSampleDistance(1.0)
        mapper.SetInputData(image_data)
        mapper.SetBlendModeToComposite()
        mapper.AutoAdjustSampleDistancesOff()
        mapper.SetImageSampleDistance(1.0)

        actor = vtk.vtkVolume()
        actor.SetMapper(mapper)
        actor.SetProperty(prop)

        ren = vtk.vtkRenderer()
        ren.SetBackground(0.0, 0.0, 0.0)
        ren.AddVolume(actor)
        # A headlight, as Tessera's default light.
        ren.RemoveAllLights()
        light = vtk.vtkLight()
        light.SetLightTypeToHeadlight()
        ren.AddLight(light)
        ren.SetAutomaticLightCreation(False)

        win = vtk.vtkRenderWindow()
        win.SetOffScreenRendering(True)
        win.SetMultiSamples(0)
        win.AddRenderer(ren)
        self.mapper, self.renderer, self.window, self.property = mapper, ren, win, prop
        self.camera = ren.GetActiveCamera()
        self.camera.SetViewAngle(30.0)
        self.camera.ParallelProjectionOff()

    def configure(self, cfg):
        """Image size, sample distance and shading of one configuration."""
        ds = self.volume.sample_distance(cfg["step"])
        self.mapper.SetSampleDistance(ds)
        if self.kind == "vtk-cpu":
            self.mapper.SetInteractiveSampleDistance(ds)
        self.property.SetShade(1 if cfg["shade"] else 0)
        self.window.SetSize(cfg["width"], cfg["height"])

    def _look(self, azimuth):
        eye, focal, up = tessera_camera(self.volume, azimuth)
        self.camera.SetFocalPoint(*focal)
        self.camera.SetPosition(*eye)
        self.camera.SetViewUp(*up)
        self.renderer.ResetCameraClippingRange()

    def frame_ms(self, azimuth):
        """One frame: Render + WaitForCompletion (glFinish), as Tessera's."""
        self._look(azimuth)
        t0 = time.perf_counter()
        self.window.Render()
        self.window.WaitForCompletion()
        return (time.perf_counter() - t0) * 1000.0

    def image(self, azimuth):
        """RGB uint8, top row first, at the given azimuth (not timed)."""
        from vtk.util import numpy_support

        self._look(azimuth)
        # Twice: the first render of a fresh off-screen window can use the
        # window's default aspect (seen with the fixed-point mapper at
        # 1024x768: a stretched image, 19 dB).
        self.window.Render()
        self.window.Render()
        grab = self.vtk.vtkWindowToImageFilter()
        grab.SetInput(self.window)
        grab.SetInputBufferTypeToRGB()
        grab.ReadFrontBufferOff()
        grab.Update()
        out = grab.GetOutput()
        w, h, _ = out.GetDimensions()
        rgb = numpy_support.vtk_to_numpy(out.GetPointData().GetScalars()).reshape(h, w, -1)
        return np.ascontiguousarray(rgb[::-1, :, :3])

    def close(self):
        self.window.Finalize()


def vtk_image_data(volume):
    import vtk
    from vtk.util import numpy_support

    image = vtk.vtkImageData()
    image.SetDimensions(*(int(d) for d in volume.dims))
    image.SetSpacing(*(float(s) for s in volume.spacing))
    image.SetOrigin(0.0, 0.0, 0.0)
    flat = np.ascontiguousarray(volume.data.ravel(order="F"))  # x fastest, as VTK stores
    scalars = numpy_support.numpy_to_vtk(flat, deep=True)
    scalars.SetName("scalars")
    image.GetPointData().SetScalars(scalars)
    return image


# --------------------------------------------------------------------------
# Images


def read_png_rgb(path):
    """Tessera's PNG as RGB uint8 (top row first)."""
    import matplotlib.image

    img = matplotlib.image.imread(path)  # float in [0,1] for PNGs
    return np.rint(img[:, :, :3] * 255.0).astype(np.uint8)


def psnr(a, b):
    mse = np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2)
    return float("inf") if mse == 0 else 10.0 * math.log10(255.0**2 / mse)


def footprint_iou(a, b, level=8):
    """Overlap of the pixels brighter than `level` in either image: a framing
    check that does not care about shading differences inside the head."""
    ma, mb = a.max(axis=2) > level, b.max(axis=2) > level
    union = np.logical_or(ma, mb).sum()
    return 1.0 if union == 0 else float(np.logical_and(ma, mb).sum() / union)


# --------------------------------------------------------------------------
# The run


def configurations(args):
    for size in args.sizes.split(","):
        w, h = (int(v) for v in size.lower().split("x"))
        for step in (float(s) for s in args.steps.split(",")):
            for shade in args.shading.split(","):
                yield {"width": w, "height": h, "step": step, "shade": shade == "on",
                       "frames": args.frames, "rounds": args.rounds, "rotate": args.rotate}


# The ablation (--ablation): Tessera's sampling levers one at a time, in the
# same alternation. "tessera" itself runs with tessera render's defaults.
ABLATION = {
    "baseline": ["--preintegrate", "off", "--adaptive", "off"],
    "+preint": ["--preintegrate", "on", "--adaptive", "off"],
    "+adaptive": ["--preintegrate", "off", "--adaptive", "on"],
    "+preint +adaptive": ["--preintegrate", "on", "--adaptive", "on"],
}
# Shaded rows only: the defaults with the gradient taken on the fly (6 fetches
# per lit sample) instead of the precomputed texture (docs/shading.md).
SHADED_ABLATION = {
    "defaults, gradient on the fly": ["--gradient", "on-the-fly"],
}


def run_configuration(cfg, tessera, vtks, workdir, log, variants=None, fine_step=0.0):
    label = (f"{cfg['width']}x{cfg['height']} step {cfg['step']:g} "
             f"{'shaded' if cfg['shade'] else 'unshaded'}")
    variants = dict(variants or {})
    if cfg["shade"] and variants:
        variants.update(SHADED_ABLATION)
    for r in vtks.values():
        r.configure(cfg)
    fine = None
    if fine_step > 0:
        fine, _ = tessera.fine_reference(cfg, fine_step, os.path.join(workdir, "fine.png"))
    # Warm-up (not timed): VTK's first Render compiles shaders and uploads the
    # volume, what Tessera does in prepare() before its frames. It also
    # gives the frame at azimuth 0 for the PSNR.
    images = {k: r.image(0.0) for k, r in vtks.items()}
    ms = {k: [] for k in RENDERERS}
    variant_ms = {k: [] for k in variants}
    variant_images = {}
    per_round = [cfg["frames"] // cfg["rounds"]] * cfg["rounds"]
    per_round[-1] += cfg["frames"] - sum(per_round)
    first = 0
    tessera_report = None
    for rnd, count in enumerate(per_round):
        azimuths = [(first + i) * cfg["rotate"] for i in range(count)]
        png = os.path.join(workdir, f"tessera-{rnd}.png")
        times, report = tessera.frames(cfg, azimuths[0], count, png)
        ms["tessera"] += times
        if rnd == 0:
            images["tessera"] = read_png_rgb(png)
            tessera_report = report
        for name, args in variants.items():
            vpng = os.path.join(workdir, f"variant-{rnd}.png")
            vtimes, _ = tessera.frames(cfg, azimuths[0], count, vpng, args)
            variant_ms[name] += vtimes
            if rnd == 0:
                variant_images[name] = read_png_rgb(vpng)
        for k, r in vtks.items():
            ms[k] += [r.frame_ms(a) for a in azimuths]
        first += count
        log(f"  {label}: round {rnd + 1}/{cfg['rounds']}: " + ", ".join(
            f"{k} {statistics.median(ms[k][-count:]):.1f} ms" for k in RENDERERS))
    row = dict(cfg)
    row["label"] = label
    for k in RENDERERS:
        row[f"{k}_ms_median"] = statistics.median(ms[k])
        row[f"{k}_ms_min"] = min(ms[k])
        row[f"{k}_frame_ms"] = ms[k]
    row["speedup_vs_vtk_cpu"] = row["vtk-cpu_ms_median"] / row["tessera_ms_median"]
    row["speedup_vs_vtk_gpu"] = row["vtk-gpu_ms_median"] / row["tessera_ms_median"]
    for k in RENDERERS[1:]:
        row[f"psnr_vs_{k}"] = psnr(images["tessera"], images[k])
        row[f"footprint_iou_vs_{k}"] = footprint_iou(images["tessera"], images[k])
    row["psnr_vtk_cpu_vs_vtk_gpu"] = psnr(images["vtk-cpu"], images["vtk-gpu"])
    row["fine_step"] = fine_step
    row["psnr_vs_fine"] = psnr(images["tessera"], fine) if fine is not None else None
    row["sampling"] = {k: tessera_report.get(k) for k in (
        "step_voxels", "preintegrate", "adaptive", "adaptive_tolerance", "adaptive_max")}
    row["variants"] = {}
    for name in variants:
        med = statistics.median(variant_ms[name])
        row["variants"][name] = {
            "ms_median": med, "frame_ms": variant_ms[name],
            "speedup_vs_vtk_cpu": row["vtk-cpu_ms_median"] / med,
            "speedup_vs_vtk_gpu": row["vtk-gpu_ms_median"] / med,
            "psnr_vs_fine": psnr(variant_images[name], fine) if fine is not None else None,
        }
    row["tessera_layout"] = tessera_report.get("layout")
    row["gl_renderer"] = tessera_report.get("gl_renderer")
    row["images"] = images
    return row


def db(v):
    if v is None:
        return "—"
    return "∞" if math.isinf(v) else f"{v:.1f} dB"


def markdown(rows, meta):
    fine = meta.get("fine_step") or 0
    lines = [
        f"Tessera vs VTK {meta['vtk_version']}: {meta['volume']} "
        f"({'x'.join(str(d) for d in meta['dims'])}), TF `{meta['tf']}`, "
        f"{meta['frames']} frames rotating {meta['rotate']:g} deg per renderer in "
        f"{meta['rounds']} alternating rounds; Tessera GL: {meta['gl_renderer']}. "
        "Frame = render + glFinish, medians in ms; speed-up = VTK median / Tessera median. "
        "Tessera runs with `tessera render`'s defaults at the same nominal step as VTK "
        "(docs/sampling.md)"
        + (f"; its image is also judged against the {fine:g}-voxel reference "
           "(every sample, post-classified)." if fine else "."),
        "",
        "| image | step (voxel) | shading | Tessera ms | VTK CPU ms | VTK GPU ms "
        "| × vs VTK CPU | × vs VTK GPU | PSNR vs CPU | PSNR vs GPU | VTK CPU vs GPU | footprint IoU CPU/GPU "
        + (f"| Tessera vs {fine:g}-step ref " if fine else "") + "|",
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|" + ("---:|" if fine else ""),
    ]
    for r in rows:
        lines.append(
            f"| {r['width']}×{r['height']} | {r['step']:g} | {'on' if r['shade'] else 'off'} "
            f"| {r['tessera_ms_median']:.1f} | {r['vtk-cpu_ms_median']:.1f} "
            f"| {r['vtk-gpu_ms_median']:.1f} | {r['speedup_vs_vtk_cpu']:.2f} "
            f"| {r['speedup_vs_vtk_gpu']:.2f} | {db(r['psnr_vs_vtk-cpu'])} "
            f"| {db(r['psnr_vs_vtk-gpu'])} | {db(r['psnr_vtk_cpu_vs_vtk_gpu'])} "
            f"| {r['footprint_iou_vs_vtk-cpu']:.3f} / "
            f"{r['footprint_iou_vs_vtk-gpu']:.3f} |"
            + (f" {db(r['psnr_vs_fine'])} |" if fine else ""))
    if any(r.get("variants") for r in rows):
        lines += [
            "",
            "Ablation, in the same alternation: Tessera with each sampling lever on its own "
            "(baseline: post-classification, every sample of the nominal step, the old "
            "behaviour; +preint: pre-integrated classification; +adaptive: adaptive steps; "
            "both: the defaults; shaded rows: every variant takes the precomputed gradient "
            "texture, the defaults' choice on ES 3, and 'defaults, gradient on the fly' takes "
            "central differences instead, 6 fetches per lit sample).",
            "",
            "| image | step | shading | variant | Tessera ms | × vs VTK CPU | × vs VTK GPU "
            + (f"| vs {fine:g}-step ref " if fine else "") + "|",
            "|---|---:|---|---|---:|---:|---:|" + ("---:|" if fine else ""),
        ]
        for r in rows:
            for name, v in r["variants"].items():
                lines.append(
                    f"| {r['width']}×{r['height']} | {r['step']:g} "
                    f"| {'on' if r['shade'] else 'off'} | {name} | {v['ms_median']:.1f} "
                    f"| {v['speedup_vs_vtk_cpu']:.2f} | {v['speedup_vs_vtk_gpu']:.2f} |"
                    + (f" {db(v['psnr_vs_fine'])} |" if fine else ""))
    for note in meta["notes"]:
        lines += ["", note]
    return "\n".join(lines) + "\n"


def write_outputs(rows, meta, out):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    os.makedirs(out, exist_ok=True)
    md = markdown(rows, meta)
    with open(os.path.join(out, "peers.md"), "w") as f:
        f.write(md)
    plain = [{k: v for k, v in r.items() if k != "images"} for r in rows]
    for r in plain:
        for k, v in list(r.items()):
            if isinstance(v, float) and math.isinf(v):
                r[k] = None
    with open(os.path.join(out, "peers.json"), "w") as f:
        json.dump({"meta": meta, "rows": plain}, f, indent=2)
    fields = ["width", "height", "step", "shade"] + [
        f"{k}_ms_median" for k in RENDERERS] + [
        "speedup_vs_vtk_cpu", "speedup_vs_vtk_gpu", "psnr_vs_vtk-cpu", "psnr_vs_vtk-gpu",
        "footprint_iou_vs_vtk-cpu", "footprint_iou_vs_vtk-gpu", "psnr_vs_fine"]
    with open(os.path.join(out, "peers.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(plain)
    # Bars: median ms per renderer per configuration.
    fig, ax = plt.subplots(figsize=(max(6, 1.6 * len(rows) + 2), 4.5))
    x = np.arange(len(rows))
    for i, (k, colour) in enumerate(zip(RENDERERS, ("#1b7837", "#762a83", "#e08214"))):
        vals = [r[f"{k}_ms_median"] for r in rows]
        ax.bar(x + (i - 1) * 0.27, vals, 0.27, label=k, color=colour)
    for xi, r in zip(x, rows):
        ax.text(xi, max(r[f"{k}_ms_median"] for k in RENDERERS) * 1.02,
                f"×{r['speedup_vs_vtk_cpu']:.2f} / ×{r['speedup_vs_vtk_gpu']:.2f}",
                ha="center", va="bottom", fontsize=8)
    ax.set_ylim(top=1.12 * max(r[f"{k}_ms_median"] for r in rows for k in RENDERERS))
    ax.set_xticks(x)
    ax.set_xticklabels([r["label"].replace(" step", "\nstep") for r in rows], fontsize=8)
    ax.set_ylabel("median ms per frame (lower is better)")
    ax.set_title(f"Tessera vs VTK {meta['vtk_version']} ({os.path.basename(meta['volume'])}, "
                 f"TF {meta['tf']}); labels: speed-up vs CPU / GPU", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "peers.png"), dpi=110)
    plt.close(fig)
    # The compared frames, side by side, for a look at the framing.
    for r in rows:
        strip = np.concatenate([r["images"][k] for k in RENDERERS], axis=1)
        name = f"frames-{r['width']}x{r['height']}-step{r['step']:g}-{'shaded' if r['shade'] else 'unshaded'}.png"
        plt.imsave(os.path.join(out, name), strip)
    return md


def smoke_volume(path):
    """A small LAS-stored (x flipped) NIfTI with an off-centre bright block, so
    that orientation and framing mistakes show in the PSNR."""
    import nibabel as nib

    n = 40
    z, y, x = np.meshgrid(*(np.arange(n),) * 3, indexing="ij")
    r = np.sqrt((x - 20.0) ** 2 + (y - 18.0) ** 2 + (z - 21.0) ** 2)
    data = np.clip(220.0 - 12.0 * np.abs(r - 12.0), 0, 255)
    data[4:12, 26:34, 28:36] = 250.0  # (z, y, x): inferior, and x 28..35 is the patient's left
    data = np.transpose(data, (2, 1, 0)).astype(np.uint8)  # stored x fastest
    affine = np.diag([-1.0, 1.2, 1.0, 1.0])
    affine[:3, 3] = [20.0, -24.0, -20.0]
    nib.save(nib.Nifti1Image(data, affine), path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tessera", default=os.path.join(REPO, "build", "tessera"),
                    help="the tessera binary (default: build/tessera)")
    ap.add_argument("--volume", default=DEFAULT_VOLUME, help="a NIfTI file (default: ch2)")
    ap.add_argument("--tf", default="bench",
                    help="Tessera TF preset or JSON file, translated into VTK's functions")
    ap.add_argument("--sizes", default="512x512,1024x768", help="comma-separated WxH")
    ap.add_argument("--steps", default="0.5,1.0",
                    help="sample distances in voxels of the smallest spacing")
    ap.add_argument("--shading", default="off,on", help="off, on or off,on")
    ap.add_argument("--frames", type=int, default=36, help="frames per renderer and configuration")
    ap.add_argument("--rounds", type=int, default=6,
                    help="alternating rounds the frames are split into")
    ap.add_argument("--rotate", type=float, default=10.0, help="azimuth step per frame, degrees")
    ap.add_argument("--ambient", type=float, default=0.1)
    ap.add_argument("--diffuse", type=float, default=0.7)
    ap.add_argument("--specular", type=float, default=0.2)
    ap.add_argument("--shininess", type=float, default=10.0)
    ap.add_argument("--tessera-args", default="",
                    help="extra arguments for tessera render (space-separated)")
    ap.add_argument("--ablation", action="store_true",
                    help="also run Tessera with each sampling lever alone (baseline / +preint / "
                         "+adaptive / both) in the same alternation")
    ap.add_argument("--fine-step", type=float, default=0.25,
                    help="judge Tessera's frame at azimuth 0 against its CPU reference at this "
                         "step (every sample, post-classified); 0: skip")
    ap.add_argument("--out", default=os.path.join(REPO, "out", "peers"),
                    help="folder for peers.md/.json/.csv/.png and the compared frames")
    ap.add_argument("--smoke", action="store_true",
                    help="a tiny case in seconds (40^3 LAS volume, 96x80, 2 frames); fails "
                         "unless the images match (PSNR >= --min-psnr)")
    ap.add_argument("--min-psnr", type=float, default=30.0,
                    help="with --smoke: the PSNR Tessera vs each VTK mapper must reach")
    args = ap.parse_args()

    if not os.environ.get("DISPLAY") and not os.environ.get("TESSERA_PEERS_NO_XVFB"):
        if not shutil.which("xvfb-run"):
            raise SystemExit("VTK needs an X server here: install xvfb (xvfb-run)")
        os.environ["TESSERA_PEERS_NO_XVFB"] = "1"
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", XVFB_SCREEN, sys.executable] + sys.argv)

    import vtk

    workdir = tempfile.mkdtemp(prefix="tessera-peers-")
    try:
        if args.smoke:
            args.volume = os.path.join(workdir, "smoke.nii.gz")
            smoke_volume(args.volume)
            args.sizes, args.steps, args.frames, args.rounds = "96x80", "1.0", 2, 2
            args.shading = "off"
            if args.out == os.path.join(REPO, "out", "peers"):
                args.out = os.path.join(workdir, "out")
        log = lambda msg: print(msg, file=sys.stderr, flush=True)  # noqa: E731
        tessera = Tessera(args.tessera, args.volume, args.tf, args.tessera_args.split())
        tf = tessera.transfer_function()
        volume = PatientVolume(args.volume)
        image_data = vtk_image_data(volume)
        lighting = {k: getattr(args, k) for k in ("ambient", "diffuse", "specular", "shininess")}
        notes = []
        cfgs = list(configurations(args))
        if any(c["shade"] for c in cfgs) and not tessera.has_shade:
            print("shaded rows skipped: tessera has no --shade")
            notes.append("Shaded rows skipped: this tessera has no --shade.")
            cfgs = [c for c in cfgs if not c["shade"]]
        vtks = {k: VtkRenderer(k, volume, image_data, tf, lighting) for k in RENDERERS[1:]}
        variants = ABLATION if args.ablation else {}
        rows = [run_configuration(cfg, tessera, vtks, workdir, log, variants, args.fine_step)
                for cfg in cfgs]
        for r in vtks.values():
            r.close()
        meta = {
            "volume": args.volume, "dims": [int(d) for d in volume.dims],
            "spacing": [float(s) for s in volume.spacing], "tf": args.tf,
            "tf_json": tf, "value_range": [volume.value_min, volume.value_max],
            "frames": args.frames, "rounds": args.rounds, "rotate": args.rotate,
            "lighting": lighting, "vtk_version": vtk.vtkVersion.GetVTKVersion(),
            "gl_renderer": rows[0]["gl_renderer"] if rows else None,
            "tessera": args.tessera, "notes": notes, "fine_step": args.fine_step,
            "ablation": list(ABLATION) + list(SHADED_ABLATION) if args.ablation else [],
            "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()),
        }
        md = write_outputs(rows, meta, args.out)
        print(md)
        print(f"wrote {args.out}/peers.md, peers.json, peers.csv, peers.png")
        if args.smoke:
            worst = min(min(r["psnr_vs_vtk-cpu"], r["psnr_vs_vtk-gpu"]) for r in rows)
            if worst < args.min_psnr:
                raise SystemExit(f"smoke: PSNR {worst:.1f} dB < {args.min_psnr} dB: "
                                 "the images do not match")
            print(f"smoke: ok (worst PSNR {worst:.1f} dB >= {args.min_psnr} dB)")
    finally:
        shutil.rmtree(workdir, ignore_errors=True)


if __name__ == "__main__":
    main()
