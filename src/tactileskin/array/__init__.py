"""Sensor-array design: can an array of taxels under the skin tell stimuli apart?

A *map* is any pressure field on a tensor grid, `results.BoneMap` (coordinates s, z in mm,
values[j, i] at (s_i, z_j)): the bone-pressure map of a 3D solve (the paper's sensor film on
the bone), or the pressure at a sensor depth below the contact surface read from the cached
solve (chart.map_of, ChartConfig.sensor_depth). Modules:

- halfspace: the elastic half-space as a spatial low-pass filter (closed forms).
- sampler: a map read by an array (pitch, taxel area averaging, offsets, rotation, noise, bits).
- classify: nearest-template and linear (scikit-learn) classifiers, accuracy and confusion.
- surrogate: Braille characters' maps by superposing single-dot responses, and its validation.
- chart: the design chart (accuracy over thickness x pitch x noise) and its verdicts.
"""
