"""Render an oracle-contract glTF scene with Mitsuba 3 (scalar_rgb, path) and time it.

`hush-cli bench --mitsuba` runs this beside its own tracer so both rates come from one run on
one machine. The scene must follow the conventions of the oracle scenes (shared/oracle/README.md):
one triangle primitive per mesh with float32 POSITION and NORMAL and uint32 indices, materials
Lambertian / mirror / rough metal / glass (smooth or rough dielectric), area emission, point and directional lights, a constant
environment, a perspective or thin-lens camera. Anything else is refused with an error.

Usage: mitsuba_time.py SCENE.gltf --width W --height H --spp N [--seed S] [--out image.exr]
Prints one JSON line: {"seconds": render seconds, "samples_per_second": ..., "mean_rgb": [...]}.
"""
import argparse, json, math, os, sys, time

import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")


def fail(msg):
    print(json.dumps({"error": msg}))
    sys.exit(2)


def quat_mat(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0],
        [0, 0, 0, 1]])


def local(node):
    if "matrix" in node:
        return np.array(node["matrix"], dtype=np.float64).reshape(4, 4).T
    t = np.eye(4)
    t[:3, 3] = node.get("translation", [0, 0, 0])
    s = np.diag(list(node.get("scale", [1, 1, 1])) + [1])
    return t @ quat_mat(node.get("rotation", [0, 0, 0, 1])) @ s


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--width", type=int, required=True)
    ap.add_argument("--height", type=int, required=True)
    ap.add_argument("--spp", type=int, required=True)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out")
    a = ap.parse_args()
    g = json.load(open(a.scene))
    base = os.path.dirname(os.path.abspath(a.scene))
    bufs = []
    for b in g["buffers"]:
        uri = b.get("uri", "")
        if uri.startswith("data:") or "/" in uri or "\\" in uri:
            fail(f"buffer {uri[:40]!r}: only a .bin beside the .gltf is read")
        bufs.append(open(os.path.join(base, uri), "rb").read())

    def accessor(i, comps, dtype):
        acc = g["accessors"][i]
        bv = g["bufferViews"][acc["bufferView"]]
        if bv.get("byteStride", 0) not in (0, comps * 4):
            fail("interleaved vertex data is out of contract")
        off = bv.get("byteOffset", 0) + acc.get("byteOffset", 0)
        return np.frombuffer(bufs[bv["buffer"]], dtype=dtype, count=acc["count"] * comps, offset=off).reshape(-1, comps)

    world = {}
    def walk(i, parent):
        world[i] = parent @ local(g["nodes"][i])
        for c in g["nodes"][i].get("children", []):
            walk(c, world[i])
    for r in g["scenes"][0]["nodes"]:
        walk(r, np.eye(4))

    extras = g["scenes"][0].get("extras", {})
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": int(extras.get("max_depth", 6)), "rr_depth": 5, "hide_emitters": False}}
    env = extras.get("environment")
    if env:
        scene["env"] = {"type": "constant", "radiance": {"type": "rgb", "value": env["radiance"]}}
    lights = g.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for i, m in world.items():
        node = g["nodes"][i]
        if "camera" in node:
            cam = g["cameras"][node["camera"]]
            if cam["type"] != "perspective":
                fail("only perspective cameras are in contract")
            p = cam["perspective"]
            ce = cam.get("extras", {})
            to_world = mi.ScalarTransform4f((m @ np.diag([-1, 1, -1, 1])).tolist())
            sensor = {"type": "thinlens" if "aperture_radius" in ce else "perspective", "fov_axis": "y", "fov": math.degrees(p["yfov"]),
                      "near_clip": p["znear"], "far_clip": p["znear"] * 1e6, "to_world": to_world,
                      "sampler": {"type": "independent", "sample_count": a.spp},
                      "film": {"type": "hdrfilm", "width": a.width, "height": a.height, "rfilter": {"type": "box"}, "pixel_format": "rgb"}}
            if "aperture_radius" in ce:
                sensor["aperture_radius"] = ce["aperture_radius"]
                sensor["focus_distance"] = ce["focus_distance"]
            scene["sensor"] = sensor
        li = node.get("extensions", {}).get("KHR_lights_punctual")
        if li is not None:
            l = lights[li["light"]]
            e = [c * l.get("intensity", 1.0) for c in l.get("color", [1, 1, 1])]
            if l["type"] == "point":
                scene[f"light{i}"] = {"type": "point", "position": m[:3, 3].tolist(), "intensity": {"type": "rgb", "value": e}}
            elif l["type"] == "directional":
                d = (m[:3, :3] @ np.array([0, 0, -1.0])).tolist()
                scene[f"light{i}"] = {"type": "directional", "direction": d, "irradiance": {"type": "rgb", "value": e}}
            else:
                fail(f"{l['type']} lights are out of contract")
        if "mesh" not in node:
            continue
        prims = g["meshes"][node["mesh"]]["primitives"]
        if len(prims) != 1 or prims[0].get("mode", 4) != 4:
            fail("one triangle primitive per mesh is in contract")
        pr = prims[0]
        pos = accessor(pr["attributes"]["POSITION"], 3, np.float32).astype(np.float64)
        nrm = accessor(pr["attributes"]["NORMAL"], 3, np.float32).astype(np.float64)
        idx = accessor(pr["indices"], 1, np.uint32).reshape(-1, 3)
        pos = (m @ np.c_[pos, np.ones(len(pos))].T).T[:, :3]
        nrm = (np.linalg.inv(m[:3, :3]).T @ nrm.T).T
        nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
        mat = g["materials"][pr.get("material", 0)] if "material" in pr else {}
        pbr = mat.get("pbrMetallicRoughness", {})
        c = pbr.get("baseColorFactor", [1, 1, 1, 1])[:3]
        metallic, rough = pbr.get("metallicFactor", 1.0), pbr.get("roughnessFactor", 1.0)
        ext = mat.get("extensions", {})
        glass = ext.get("KHR_materials_transmission", {}).get("transmissionFactor", 0.0)
        if glass > 0.0:
            # Contract (d): a closed volume of exact dielectric, white, no attenuation.
            ior = ext.get("KHR_materials_ior", {}).get("ior", 1.5)
            thick = ext.get("KHR_materials_volume", {}).get("thicknessFactor", 0.0)
            if glass != 1.0 or metallic != 0.0 or c != [1, 1, 1] or thick <= 0.0 or not mat.get("doubleSided"):
                fail(f"glass {mat.get('name')!r} is out of contract")
            if rough == 0.0:
                bsdf = {"type": "dielectric", "int_ior": ior, "ext_ior": 1.0}
            else:
                bsdf = {"type": "roughdielectric", "distribution": "ggx", "alpha": max(rough * rough, 1e-4), "int_ior": ior, "ext_ior": 1.0}
        elif metallic == 0.0 and ext.get("KHR_materials_specular", {}).get("specularFactor", 1.0) == 0.0:
            bsdf = {"type": "diffuse", "reflectance": {"type": "rgb", "value": c}}
        elif metallic == 1.0 and rough == 0.0:
            bsdf = {"type": "conductor", "material": "none", "specular_reflectance": {"type": "rgb", "value": c}}
        elif metallic == 1.0:
            bsdf = {"type": "roughconductor", "distribution": "ggx", "alpha": max(rough * rough, 1e-4), "material": "none", "specular_reflectance": {"type": "rgb", "value": c}}
        else:
            fail(f"material {mat.get('name')!r} is out of contract")
        if mat.get("doubleSided") and glass == 0.0:
            bsdf = {"type": "twosided", "bsdf": bsdf}
        props = mi.Properties()
        props["bsdf"] = mi.load_dict(bsdf)
        emissive = mat.get("emissiveFactor")
        if emissive and max(emissive) > 0:
            s = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
            props["emitter"] = mi.load_dict({"type": "area", "radiance": {"type": "rgb", "value": [x * s for x in emissive]}})
        mesh = mi.Mesh(f"mesh{i}", len(pos), len(idx), props=props, has_vertex_normals=True)
        params = mi.traverse(mesh)
        params["vertex_positions"] = pos.astype(np.float32).ravel().tolist()
        params["vertex_normals"] = nrm.astype(np.float32).ravel().tolist()
        params["faces"] = idx.astype(np.uint32).ravel().tolist()
        params.update()
        scene[f"mesh{i}"] = mesh
    if "sensor" not in scene:
        fail("no camera")
    t0 = time.perf_counter()
    sc = mi.load_dict(scene)
    load_s = time.perf_counter() - t0
    t0 = time.perf_counter()
    img = mi.render(sc, spp=a.spp, seed=a.seed)
    img = np.array(img)
    secs = time.perf_counter() - t0
    if a.out:
        mi.util.write_bitmap(a.out, img)
    print(json.dumps({"seconds": secs, "load_seconds": load_s, "samples_per_second": a.width * a.height * a.spp / secs,
                      "mean_rgb": img.reshape(-1, 3).mean(axis=0).tolist()}))


if __name__ == "__main__":
    main()
