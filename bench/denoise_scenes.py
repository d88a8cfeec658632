#!/usr/bin/env python3
"""Varied sphere scenes for measuring the denoiser on scenes it was not tuned on.

    python3 bench/denoise_scenes.py OUT_DIR [--tune N] [--eval N] [--size PX] [--spp N]

writes OUT_DIR/tune_NN.json (seeds 1000 + NN) and OUT_DIR/eval_NN.json (seeds 2000 + NN),
each deterministic by its seed (Python's own Mersenne Twister, no other dependency): 5 to 200
spheres of log-uniform sizes on a floor, in an open scene (black sky) or a room of wall
spheres; diffuse, glossy, mirror, glass and translucent materials; 1 to 3 lights, each a
point light or an area light (a sphere of radius 0.15 to 1.5) of several colours; a pinhole
or a thin lens focused on one of the spheres. Lights are scaled so that a diffuse surface
near the middle of the scene is lit to about the same level (an irradiance of about 6) in every scene (the relMSE's
floor of 0.01 then weighs alike). `scripts/bench_denoise.sh` regenerates them and measures the
final filter on them; the tuning set is what filter changes are measured on while they are
made, the evaluation set is only reported.
"""
import argparse
import json
import math
import os
import random


def colour(rng, lo=0.05, hi=0.95):
    # A saturated colour half the time, a grey otherwise.
    if rng.random() < 0.5:
        g = rng.uniform(lo, hi)
        return [round(g, 3)] * 3
    return [round(rng.uniform(lo, hi), 3) for _ in range(3)]


def material(rng, index):
    kind = rng.choices(["diffuse", "glossy", "mirror", "glass", "translucent"], [0.5, 0.18, 0.12, 0.12, 0.08])[0]
    mid = f"m{index:03d}"
    if kind == "diffuse":
        return {"id": mid, "type": "diffuse", "rho": colour(rng)}
    if kind == "glossy":
        return {"id": mid, "type": "glossy reflection", "rho": colour(rng, 0.2, 0.95),
                "roughness": round(rng.uniform(0.05, 0.5), 3)}
    if kind == "mirror":
        return {"id": mid, "type": "specular reflection", "rho": colour(rng, 0.6, 0.95)}
    t = [round(rng.uniform(0.8, 1.0), 3)] * 3
    m = {"id": mid, "type": "fresnel dielectric", "rhoR": t, "rhoT": t, "eta": round(rng.uniform(1.3, 1.7), 3)}
    if kind == "translucent":
        m["type"] = "translucent dielectric"
        m["roughness"] = round(rng.uniform(0.05, 0.3), 3)
    return m


def scene(seed, size, spp):
    rng = random.Random(seed)
    count = int(round(math.exp(rng.uniform(math.log(5), math.log(200)))))
    # Sizes: log-uniform radii, the spread area grows with the count so that they fit.
    r_lo, r_hi = 0.15, rng.uniform(0.5, 1.6)
    extent = max(2.0, 0.9 * math.sqrt(count) * (r_lo + r_hi) / 2 * 1.6)
    materials = [{"id": "floor", "type": "diffuse", "rho": colour(rng, 0.3, 0.85)},
                 {"id": "wall", "type": "diffuse", "rho": colour(rng, 0.4, 0.85)},
                 {"id": "lamp", "type": "diffuse", "rho": [1, 1, 1]}]
    palette = [material(rng, k) for k in range(rng.randint(3, 10))]
    materials += palette
    shapes = [{"id": "floor", "type": "sphere", "centre": [0, -10000, 0], "radius": 10000}]
    primitives = [{"id": "floor", "type": "geometric", "shape": "floor", "material": "floor"}]
    room = rng.random() < 0.5
    if room:
        far = extent * 1.6
        for name, centre in (("back", [0, 0, far + 10000]), ("left", [-far - 10000, 0, 0]),
                             ("right", [far + 10000, 0, 0])):
            shapes.append({"id": name, "type": "sphere", "centre": centre, "radius": 10000})
            primitives.append({"id": name, "type": "geometric", "shape": name, "material": "wall"})
    placed = []
    tries = 0
    while len(placed) < count and tries < 20000:
        tries += 1
        r = math.exp(rng.uniform(math.log(r_lo), math.log(r_hi)))
        x, z = rng.uniform(-extent, extent), rng.uniform(-extent, extent)
        y = r if rng.random() < 0.8 else r + rng.uniform(0.2, 2.0)
        if any((x - a) ** 2 + (y - b) ** 2 + (z - c) ** 2 < (r + s + 0.02) ** 2 for a, b, c, s in placed):
            continue
        placed.append((x, y, z, r))
    for k, (x, y, z, r) in enumerate(placed):
        sid = f"s{k:03d}"
        shapes.append({"id": sid, "type": "sphere", "centre": [round(x, 4), round(y, 4), round(z, 4)],
                       "radius": round(r, 4)})
        primitives.append({"id": sid, "type": "geometric", "shape": sid, "material": rng.choice(palette)["id"]})
    # Lights above the spheres: their irradiance at the middle of the floor sums to about 6.
    lights, light_ids = [], []
    n_lights = rng.randint(1, 3)
    top = max(y + r for _, y, _, r in placed)
    for k in range(n_lights):
        lid = f"light {k}"
        pos = [rng.uniform(-extent, extent), top + rng.uniform(1.5, 2.5 + extent), rng.uniform(-extent, extent * 0.5)]
        d2 = sum(p * p for p in pos)
        share = 6.0 / n_lights * rng.uniform(0.5, 1.5)
        tint = [rng.uniform(0.6, 1.0) for _ in range(3)]
        if rng.random() < 0.35:
            power = [round(share * d2 * t, 3) for t in tint]
            lights.append({"id": lid, "type": "point", "position": [round(p, 4) for p in pos], "power": power})
        else:
            radius = math.exp(rng.uniform(math.log(0.15), math.log(1.5)))
            if any((pos[0] - a) ** 2 + (pos[1] - b) ** 2 + (pos[2] - c) ** 2 < (radius + s + 0.05) ** 2
                   for a, b, c, s in placed):
                pos[1] = top + radius + 0.5
            power = [round(share * d2 / (math.pi * radius * radius) * t, 3) for t in tint]
            shapes.append({"id": lid, "type": "sphere", "centre": [round(p, 4) for p in pos], "radius": round(radius, 4)})
            lights.append({"id": lid, "type": "area", "shape": lid, "power": power})
            primitives.append({"id": lid, "type": "emissive", "shape": lid, "light": lid, "material": "lamp"})
        light_ids.append(lid)
    # The camera: in front, above, looking at the spheres' middle.
    dist = extent * rng.uniform(1.1, 1.9) + 2
    elev = rng.uniform(0.15, 0.7)
    yaw = rng.uniform(-0.5, 0.5)
    target = [0, rng.uniform(0.2, 1.0), 0]
    position = [round(dist * math.sin(yaw) * math.cos(elev), 4), round(target[1] + dist * math.sin(elev), 4),
                round(-dist * math.cos(yaw) * math.cos(elev), 4)]
    camera = {"id": "camera", "type": "pinhole", "fov": round(rng.uniform(35, 60), 2), "aspect": 1.0,
              "distance": 5.0, "position": position, "target": target}
    if rng.random() < 0.5:
        x, y, z, _ = rng.choice(placed)
        focus = math.sqrt((x - position[0]) ** 2 + (y - position[1]) ** 2 + (z - position[2]) ** 2)
        camera.update({"type": "lens-based", "focal distance": round(focus, 4),
                       "alpha": round(rng.uniform(0.02, 0.12) * focus / 5, 4)})
    return {
        "cameras": [camera],
        "materials": materials,
        "shapes": shapes,
        "lights": lights,
        "scene": {"camera": "camera", "lights": light_ids, "primitives": primitives,
                  "renderer": {"type": "PT", "dimensions": [size, size], "samples": spp, "depth": 6,
                               "output": f"scene_{seed}.ppm"}},
    }


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out")
    ap.add_argument("--tune", type=int, default=8)
    ap.add_argument("--eval", type=int, default=12)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--spp", type=int, default=64, help="the files' spp")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    for prefix, base, n in (("tune", 1000, args.tune), ("eval", 2000, args.eval)):
        for k in range(n):
            with open(os.path.join(args.out, f"{prefix}_{k:02d}.json"), "w") as f:
                json.dump(scene(base + k, args.size, args.spp), f, indent=1)
                f.write("\n")


if __name__ == "__main__":
    main()
