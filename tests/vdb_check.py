#!/usr/bin/python3
"""Reads morphoflow's VDB volumes back with an independent reader (pyopenvdb)
and checks them against the float EXR field dumps of the same frames (read
with OpenImageIO's Python module): grid names, value types and classes, the
transform (voxel size = cell size, the volume fills [0, domain.size]),
metadata, values, inactive background, and NanoVDB files beside them.

usage: vdb_check.py MORPHOFLOW_BINARY SCENE_DIR WORK_DIR"""
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pyopenvdb as vdb

binary, scenes, work = sys.argv[1:4]
failures = []


def check(cond, what):
    if not cond:
        failures.append(what)
        print("FAIL:", what)


def run(name, scene, sets):
    out = os.path.join(work, name)
    shutil.rmtree(out, ignore_errors=True)
    args = [binary, "run", os.path.join(scenes, scene), "--quiet", "--out", out]
    for s in sets:
        args += ["--set", s]
    r = subprocess.run(args, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"{name}: morphoflow exited {r.returncode}: {r.stderr}")
    return out


def read_dump(path):
    """The EXR atlas as {channel: array[z, y, x]}, and its time."""
    inp = oiio.ImageInput.open(path)
    spec = inp.spec()
    pixels = inp.read_image("float")
    inp.close()
    res = list(spec.getattribute("morphoflow:resolution"))
    nx, ny = res[0], res[1]
    nz = res[2] if len(res) > 2 else 1
    out = {}
    for c, name in enumerate(spec.channelnames):
        img = pixels[:, :, c].reshape(nz, ny, nx)  # slice z: rows z ny .. (z + 1) ny - 1
        out[name] = img[:, ::-1, :]                # y up within a slice
    return out, spec.getattribute("morphoflow:time"), res


def dense(grid, shape_xyz):
    a = np.zeros(shape_xyz, dtype=np.float32 if grid.valueTypeName == "float" else np.float32)
    grid.copyToArray(a, ijk=(0, 0, 0))
    return a  # [x, y, z]


def check_volume(name, out, sets_fluid_fields, tolerance, obstacle, dims3):
    rj = json.load(open(os.path.join(out, "run.json")))
    size3 = rj["resolved"]["size"]
    shown = rj["scene"].get("output", {}).get("field")
    scene_name = rj["scene"].get("name", None) or os.path.splitext(os.path.basename(rj["scene_file"]))[0]
    species = rj["resolved"]["species"]
    shown = shown or species[0]
    vdbdir = os.path.join(out, "vdb")
    files = sorted(f for f in os.listdir(vdbdir) if f.endswith(".vdb"))
    check(len(files) == rj["frames_written"] and len(files) > 1, f"{name}: one .vdb per frame ({len(files)})")
    for f in files:
        frame = int(f.split(".")[-2])
        check(f == f"{scene_name}.{frame:06d}.vdb", f"{name}: file name {f}")
        check(os.path.exists(os.path.join(vdbdir, f[:-4] + ".nvdb")), f"{name}: {f} has a .nvdb beside it")
        grids, meta = vdb.readAll(os.path.join(vdbdir, f))
        by = {g.name: g for g in grids}
        want = set(species) | {"density", "vel"} | set(sets_fluid_fields) | ({"obstacle"} if obstacle else set())
        check(set(by) == want, f"{name} {f}: grids {sorted(by)} != {sorted(want)}")
        dump, time, res = read_dump(os.path.join(out, "fields", f"{frame:06d}.exr"))
        # Metadata.
        check(meta.get("frame") == frame, f"{name} {f}: frame metadata {meta.get('frame')}")
        check(meta.get("scene") == scene_name, f"{name} {f}: scene metadata")
        check(meta.get("settings_hash") == rj["settings_hash"], f"{name} {f}: settings hash")
        check(meta.get("morphoflow_version") == rj["version"], f"{name} {f}: version")
        check(abs(meta.get("time") - time) <= 1e-6 * max(1.0, abs(time)),
              f"{name} {f}: time {meta.get('time')} vs {time}")
        check(isinstance(meta.get("step"), int) and meta.get("dt", 0) > 0 and "units" in meta,
              f"{name} {f}: step, dt, units")
        for g in grids:
            # Transform: voxel = cell, index 0 at the first cell's centre, the volume fills [0, size].
            n = dims3
            h = size3[0] / n[0]
            check(all(abs(v - h) < 1e-9 for v in g.transform.voxelSize()), f"{name} {f} {g.name}: voxel size")
            lo = g.transform.indexToWorld((0, 0, 0))
            hi = g.transform.indexToWorld((n[0] - 1, n[1] - 1, n[2] - 1))
            for a in range(3):
                check(abs(lo[a] - 0.5 * h) < 1e-9 and abs(hi[a] + 0.5 * h - (size3[a] if a < len(size3) else h)) < 1e-6,
                      f"{name} {f} {g.name}: world bounds axis {a}")
        for s in species + ["density"]:
            g = by[s]
            check(g.valueTypeName == "float", f"{name} {f} {s}: float")
            check(g.gridClass == ("fog volume" if s == "density" else "unknown"),
                  f"{name} {f} {s}: class {g.gridClass}")
            ref = dump[shown if s == "density" else s].transpose(2, 1, 0)  # [x, y, z]
            got = dense(g, ref.shape)
            # Background inactive: a voxel is active exactly where |value| > tolerance,
            # and holds the dump's value; an inactive one holds the background.
            acc = g.getConstAccessor()
            on = np.zeros(ref.shape, dtype=bool)
            for idx in np.ndindex(*ref.shape):
                on[idx] = acc.isValueOn(idx)
            check(np.array_equal(on, np.abs(ref) > tolerance),
                  f"{name} {f} {s}: {int((on != (np.abs(ref) > tolerance)).sum())} voxels wrongly active or inactive")
            check(np.array_equal(got[on], ref[on]), f"{name} {f} {s}: active values equal the EXR dump")
            check(np.all(got[~on] == g.background), f"{name} {f} {s}: inactive voxels hold the background")
        vel = by["vel"]
        check(vel.valueTypeName == "vec3s" and vel.vectorType == "contravariant relative", f"{name} {f}: vel type")
        if "speed" in by:
            v = np.zeros(tuple(dims3) + (3,), dtype=np.float32)
            vel.copyToArray(v, ijk=(0, 0, 0))
            sp = dense(by["speed"], tuple(dims3))
            mag = np.sqrt((v.astype(np.float64) ** 2).sum(axis=3))
            check(np.allclose(mag, sp, rtol=1e-5, atol=1e-7), f"{name} {f}: |vel| equals the speed grid")
            if len(dims3) and dims3[2] == 1:
                check(np.all(v[:, :, :, 2] == 0), f"{name} {f}: a 2D velocity has no z component")
        if obstacle:
            ob = by["obstacle"]
            check(ob.gridClass == "level set", f"{name} {f}: obstacle is a level set")
            bg = ob.background
            check(bg > 0 and ob.activeVoxelCount() > 0, f"{name} {f}: obstacle narrow band")
            # Negative inside the solid: the centre of the first obstacle.
            c = ob.evalActiveVoxelBoundingBox()
            mid = tuple((c[0][a] + c[1][a]) // 2 for a in range(3))
            check(ob.getConstAccessor().getValue(mid) < 0, f"{name} {f}: obstacle negative inside")


# 3D: a coupled scene with an obstacle, fluid scalars, a tolerance.
d3 = run("coupled_3d", "coupled/obstacle_gray_scott_3d.toml",
         ["grid.resolution=[10,20,10]", "rd.resolution=[10,20,10]", "time.steps=6", "output.every=3",
          "output.vdb=true", "output.nanovdb=true", "output.fields=true", "output.video=false",
          'output.vdb_fields=["speed","vorticity","pressure","dye"]',
          "output.vdb_tolerance=0.05"])
check_volume("coupled_3d", d3, ["speed", "vorticity", "pressure", "dye"], 0.05, True, (10, 20, 10))
# 2D: one voxel thick, default tolerance 0.
d2 = run("coupled_2d", "coupled/cavity_gray_scott.toml",
         ["grid.resolution=[16,16]", "rd.resolution=[16,16]", "time.steps=4", "output.every=2", "output.vdb=true",
          "output.nanovdb=true", "output.fields=true", "output.video=false", 'output.vdb_fields=["speed"]'])
check_volume("coupled_2d", d2, ["speed"], 0.0, False, (16, 16, 1))
# Half floats are stored as half.
dh = run("half", "coupled/cavity_gray_scott.toml",
         ["grid.resolution=[16,16]", "rd.resolution=[16,16]", "time.steps=2", "output.every=2", "output.vdb=true",
          "output.vdb_half=true", "output.video=false"])
full = os.path.getsize(os.path.join(d2, "vdb", "cavity_gray_scott.000001.vdb"))
half = os.path.getsize(os.path.join(dh, "vdb", "cavity_gray_scott.000001.vdb"))
grids, _ = vdb.readAll(os.path.join(dh, "vdb", "cavity_gray_scott.000001.vdb"))
check(all(g.saveFloatAsHalf for g in grids), "half: every grid is saved as half")
check(half < full, f"half: smaller file ({half} vs {full} bytes)")

# Smoke: the grids renderers read by name, one shared sparse topology (active
# exactly where the dumped smoke exceeds the tolerance, in every grid), the
# values of the dump there, colour in [0, 1], and a frame much smaller than
# the same frame written densely.
def check_smoke(out, dims, tolerance):
    f = sorted(x for x in os.listdir(os.path.join(out, "vdb")) if x.endswith(".vdb"))[-1]
    frame = int(f.split(".")[-2])
    grids, _ = vdb.readAll(os.path.join(out, "vdb", f))
    by = {g.name: g for g in grids}
    check(set(by) == {"density", "temperature", "vel", "color"}, f"smoke: grids {sorted(by)}")
    dump, _, _ = read_dump(os.path.join(out, "fields", f"{frame:06d}.exr"))
    smoke = dump["dye"].transpose(2, 1, 0)
    want = smoke > tolerance
    check(0 < want.sum() < 0.5 * want.size, f"smoke: the plume fills part of the box ({want.sum()} of {want.size})")
    for g in grids:
        acc = g.getConstAccessor()
        on = np.zeros(smoke.shape, dtype=bool)
        for idx in np.ndindex(*smoke.shape):
            on[idx] = acc.isValueOn(idx)
        check(np.array_equal(on, want), f"smoke {g.name}: {int((on != want).sum())} voxels off the smoke's topology")
    check(by["density"].gridClass == "fog volume", "smoke: density is a fog volume")
    for name, ref in (("density", smoke), ("temperature", dump["temperature"].transpose(2, 1, 0))):
        got = dense(by[name], smoke.shape)
        check(np.array_equal(got[want], ref[want]), f"smoke {name}: active values equal the dump")
    col = by["color"]
    check(col.valueTypeName == "vec3s" and col.vectorType == "invariant",
          f"smoke: color is an invariant Vec3 ({col.vectorType})")
    c = np.zeros(tuple(dims) + (3,), dtype=np.float32)
    col.copyToArray(c, ijk=(0, 0, 0))
    check(c.min() >= 0 and c.max() <= 1 and len(np.unique(c[want][:, 0])) > 3, "smoke: colours in [0, 1] that vary")
    return f, want.mean()


sets = ["grid.resolution=[24,40,24]", "time.duration=0.6", "output.every=20", "output.fields=true",
        "output.images=false"]
ds = run("smoke", "vfx/plume_3d.toml", sets)
f, filled = check_smoke(ds, (24, 40, 24), 1e-3)
# The same frame with every voxel active (output.vdb_sparse = false), for the size.
dd = run("smoke_dense", "vfx/plume_3d.toml", sets + ["output.vdb_sparse=false"])
grids, _ = vdb.readAll(os.path.join(dd, "vdb", f))
check(all(g.activeVoxelCount() == 24 * 40 * 24 for g in grids), "smoke: vdb_sparse = false writes every voxel")
sparse, dense_bytes = os.path.getsize(os.path.join(ds, "vdb", f)), os.path.getsize(os.path.join(dd, "vdb", f))
print(f"smoke: {filled:.1%} of the box active: {sparse} bytes sparse, {dense_bytes} dense")
check(filled <= 0.2 and sparse <= 0.25 * dense_bytes, f"smoke: sparse {sparse} bytes vs dense {dense_bytes}")

# A patterned plume: the species (and the colour of v) on the chemicals'
# finer grid share one topology there, the fluid's grids another.
dp = run("smoke_pattern", "vfx/plume_gray_scott_3d.toml",
         ["grid.resolution=[24,40,24]", "rd.resolution=[48,80,48]", "time.duration=0.3", "output.every=15",
          "output.images=false", 'output.vdb_density="dye * v / 0.25"'])
last = sorted(x for x in os.listdir(os.path.join(dp, "vdb")) if x.endswith(".vdb"))[-1]
grids, _ = vdb.readAll(os.path.join(dp, "vdb", last))
counts = {g.name: g.activeVoxelCount() for g in grids}
check(set(counts) == {"u", "v", "color", "density", "temperature", "vel"}, f"smoke pattern: grids {sorted(counts)}")
check(counts["u"] == counts["v"] == counts["color"] > 0,
      f"smoke pattern: the chemicals' grids share a topology {counts}")
check(counts["temperature"] == counts["vel"] > 0, f"smoke pattern: the fluid's grids share one {counts}")
# density = dye * v / 0.25 lives on the chemicals' grid: 0 where v is, positive where both are.
check(counts["density"] == counts["u"], f"smoke pattern: the density expression is on the chemicals' grid {counts}")
by = {g.name: g for g in grids}
dens, v = dense(by["density"], (48, 80, 48)), dense(by["v"], (48, 80, 48))
check(np.all(dens[v == 0] == 0) and dens.max() > 0 and dens.min() >= 0, "smoke pattern: the density is smoke times v")
check(counts["u"] < 0.5 * 48 * 80 * 48, f"smoke pattern: the species are sparse ({counts['u']})")

# A density expression past a float is 0 there (as a non-finite one is), never inf.
do = run("smoke_overflow", "vfx/plume_3d.toml", ["grid.resolution=[12,20,12]", "time.duration=0.3", "output.every=30",
                                               "output.images=false", 'output.vdb_density="dye * 1e300"'])
last = sorted(x for x in os.listdir(os.path.join(do, "vdb")) if x.endswith(".vdb"))[-1]
d = vdb.read(os.path.join(do, "vdb", last), "density")
vals = np.array([v.value for v in d.citerOnValues()], dtype=np.float64)
check(vals.size > 0 and np.all(vals == 0),
      f"smoke overflow: a density past a float is 0 ({vals.size} active, {np.unique(vals)[:4]})")

# output.vdb_half: a temperature past half's range (ambient 70000) is written
# at 65504, never read back as inf, and the run says so (warning, run.json).
dh = os.path.join(work, "smoke_half")
shutil.rmtree(dh, ignore_errors=True)
r = subprocess.run([binary, "run", os.path.join(scenes, "vfx/plume_3d.toml"), "--quiet", "--out", dh,
                    "--set", "grid.resolution=[12,20,12]", "--set", "time.duration=0.3", "--set", "output.every=30",
                    "--set", "output.images=false", "--set", "output.vdb_half=true", "--set", "smoke.ambient=70000"],
                   capture_output=True, text=True)
check(r.returncode == 0, f"smoke half: exit {r.returncode} {r.stderr}")
check("'temperature'" in r.stderr and "65504" in r.stderr, f"smoke half: the warning names the grid: {r.stderr!r}")
with open(os.path.join(dh, "run.json")) as f:
    clamped = json.load(f).get("vdb_half_clamped", {})
check(clamped.get("temperature", 0) > 0 and "density" not in clamped, f"smoke half: run.json counts {clamped}")
last = sorted(x for x in os.listdir(os.path.join(dh, "vdb")) if x.endswith(".vdb"))[-1]
t = vdb.read(os.path.join(dh, "vdb", last), "temperature")
vals = np.array([v.value for v in t.citerOnValues()], dtype=np.float64)
check(vals.size > 0 and np.all(np.isfinite(vals)) and vals.max() == 65504.0,
      f"smoke half: finite, at most 65504 ({vals.max() if vals.size else None})")

print(f"vdb_check: {'FAILED' if failures else 'ok'} ({len(failures)} failures)")
sys.exit(1 if failures else 0)
