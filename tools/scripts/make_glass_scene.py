"""Write the glass parity scene, tests/mitsuba/cornell_glass, and render its Mitsuba reference.

The scene is cornell_mirror's geometry with its two objects turned to glass under the oracle
contract's material (d) (shared/oracle/README.md): the sphere a smooth dielectric, the block a
rough one (GGX roughness 0.3), both ior 1.5, closed, double-sided, without attenuation. Paths get
8 segments (the other scenes have 6) so that light crosses both glass surfaces and still reaches
a wall. The reference and an independent peer (another seed, written to the system's temp
folder: it measures the reference's own noise and is not committed) are rendered by
mitsuba_time.py, the same converter `hush-cli bench --mitsuba` uses. The oracle scenes in
tests/oracle are copies of ../shared/oracle; this one is Hush's own, so it lives apart.

Usage (from the repository root): python3 tools/scripts/make_glass_scene.py [--spp 4096]
"""
import argparse, json, os, shutil, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SRC = os.path.join(ROOT, "tests", "oracle", "cornell_mirror")
DST = os.path.join(ROOT, "tests", "mitsuba", "cornell_glass")


def glass(name, roughness):
    return {
        "name": name,
        "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0,
                                 "roughnessFactor": roughness},
        "doubleSided": True,
        "extensions": {
            "KHR_materials_transmission": {"transmissionFactor": 1.0},
            "KHR_materials_ior": {"ior": 1.5},
            "KHR_materials_volume": {"thicknessFactor": 0.5},
        },
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--peer-spp", type=int, default=256)
    ap.add_argument("--no-render", action="store_true")
    a = ap.parse_args()
    g = json.load(open(os.path.join(SRC, "cornell_mirror.gltf")))
    names = {m["name"]: i for i, m in enumerate(g["materials"])}
    g["materials"][names["mirror"]] = glass("glass", 0.0)
    g["materials"][names["metal_r03"]] = glass("rough_glass_r03", 0.3)
    for n in g["nodes"]:
        n["name"] = {"mirror_sphere": "glass_sphere", "metal_block": "glass_block"}.get(n["name"], n["name"])
    g["extensionsUsed"] = sorted(set(g["extensionsUsed"]) | {
        "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"})
    sc = g["scenes"][0]
    sc["name"] = "cornell_glass"
    sc["extras"]["max_depth"] = 8
    sc["extras"]["oracle"] = {"description": (
        "cornell_mirror with its sphere a smooth glass ball and its block rough glass (GGX "
        "roughness 0.3), both ior 1.5: refraction, total internal reflection, exact dielectric "
        "Fresnel, caustics on the floor.")}
    g["buffers"][0]["uri"] = "cornell_glass.bin"
    g["asset"]["generator"] = "hush tools/scripts/make_glass_scene.py"
    os.makedirs(DST, exist_ok=True)
    shutil.copyfile(os.path.join(SRC, "cornell_mirror.bin"), os.path.join(DST, "cornell_glass.bin"))
    gltf = os.path.join(DST, "cornell_glass.gltf")
    with open(gltf, "w") as f:
        json.dump(g, f, indent=1)
    if a.no_render:
        return
    script = os.path.join(ROOT, "tools", "scripts", "mitsuba_time.py")
    info = {}
    peer = os.path.join(tempfile.gettempdir(), "cornell_glass_peer.exr")
    for file, path, spp, seed in (("reference.exr", os.path.join(DST, "reference.exr"), a.spp, 0),
                                  ("peer.exr", peer, a.peer_spp, 1)):
        out = subprocess.run([sys.executable, script, gltf, "--width", "256", "--height", "256",
                              "--spp", str(spp), "--seed", str(seed), "--out", path],
                             check=True, capture_output=True, text=True).stdout
        r = json.loads(out.strip().splitlines()[-1])
        info[file] = {"scene": "cornell_glass", "spp": spp, "seed": seed, "seconds": round(r["seconds"], 2),
                      "variant": "scalar_rgb", "max_depth": 8, "resolution": [256, 256], "mean_rgb": r["mean_rgb"]}
        print(file, info[file], flush=True)
    with open(os.path.join(DST, "render_info.json"), "w") as f:
        json.dump(info, f, indent=1)


if __name__ == "__main__":
    main()
