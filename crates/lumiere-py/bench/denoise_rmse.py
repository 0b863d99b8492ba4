"""RMSE against a converged reference of the Cornell box (mode="path"), raw and denoised with
OIDN (color + albedo + normal), and the denoiser's time. Usage: python bench/denoise_rmse.py"""

import time

import numpy as np

import lumiere

SIZE, REFERENCE_SPP = (256, 192), 4096
scene = lumiere.builtin()
start = time.perf_counter()
reference = lumiere.render(scene, spp=REFERENCE_SPP, size=SIZE, seed=12345)
print(f"reference: {REFERENCE_SPP} spp at {SIZE[0]}x{SIZE[1]}, seed 12345, {time.perf_counter() - start:.1f} s")


def rmse(image):
    return float(np.sqrt(np.mean((image - reference) ** 2)))


print("| spp | raw RMSE | denoised RMSE | denoise time |")
print("|---|---|---|---|")
lumiere.denoise(np.ones((8, 8, 3), np.float32))  # loads OIDN and its weights once
for spp in (4, 16, 64, 256):
    out = lumiere.render(scene, spp=spp, size=SIZE, aovs=("albedo", "normal"))
    start = time.perf_counter()
    denoised = lumiere.denoise(out["color"], out["albedo"], out["normal"])
    seconds = time.perf_counter() - start
    print(f"| {spp} | {rmse(out['color']):.5f} | {rmse(denoised):.5f} | {1e3 * seconds:.0f} ms |")
