# Copyright 2026 The MultiObjectiveRegistration authors
# SPDX-License-Identifier: Apache-2.0
"""morea.register with backend="auto" on a machine with a CUDA device: the
GPU runs it, and the registration improves the phantom. Skips without a
device. Needs numpy only, so it also runs as a script where pytest and
SimpleITK are absent:  python test_cuda.py"""
import morea

PARAMETERS = {"ea_population_size": 48, "ea_num_clusters": 4, "ea_archive_size": 200, "ea_num_generations": 40,
              "morea_mesh_num_points": 300, "morea_sampling_rate": 0.5, "preprocess_isotropic_spacing": 3.0}


def test_auto_runs_on_the_gpu_when_one_is_present():
    case = morea.phantom(spacing=3.0, output="numpy")
    structures = {n: case["structures"][n] for n in ("bladder", "rectum", "bones")}
    result = morea.register(case["fixed"], case["moving"], structures=structures, landmarks=case["landmarks"],
                            parameters=PARAMETERS, backend="auto", seed=1, progress=False)
    if result.backend == "cpu":
        import pytest

        pytest.skip(f"no usable CUDA device: {result.backend_note}")
    assert result.backend == "cuda-texture", result.backend_note
    scores = result.solutions[0].scores
    before = morea.evaluate(case["fixed"], case["moving"], structures)
    assert scores["structures"]["bladder"]["dice"] > before["structures"]["bladder"]["dice"] + 0.05
    assert scores["jacobian_nonpositive_fraction"] == 0.0
    return result, scores, before


if __name__ == "__main__":
    import time

    start = time.time()
    result, scores, before = test_auto_runs_on_the_gpu_when_one_is_present()
    print(result, result.backend_note)
    print("bladder Dice", round(before["structures"]["bladder"]["dice"], 3), "->",
          round(scores["structures"]["bladder"]["dice"], 3), "; landmarks TRE", round(scores["landmarks"]["tre_mean_mm"], 2),
          "mm; seconds", round(time.time() - start, 1))
