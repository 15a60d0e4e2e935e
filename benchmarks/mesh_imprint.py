"""Mesh imprint of fractures: the rotation test and options that reduce it (issue 12).

Runs through the scene builder and Simulation (``lagice run`` subprocesses):

* ``cyclone``: ``examples/imprint_cyclone_disk.toml`` (one cyclone over a closed disk,
  neXtSIM's scaled strength, 3 days, fixed mesh) on meshes whose node lattice is
  rotated by 0°, 15° and 30° about the disk's centre (``domain.rotate_deg``: the disk
  polygon has a vertex every degree, so only the lattice turns). Fracture field:
  damage ≥ 0.5 at day 3, and the top decile of the shear rate at day 3
  (docs/physics.md §3).
* ``floor``: the same at 0°, 15°, 30° and 60° with several disorder draws each (the rotation
  test against its noise; rule above ``FLOOR_ROTATIONS``).
* ``turn``: ensembles of 12 draws at 0°, 15° and 30° with disjoint seeds, judged at exactly the
  turn with a bootstrap interval (rule above ``TURN_SEEDS``); figure ``mesh_imprint_turn.png`` for the
  variants ``base delaunay``, ``mesh_imprint_turn_VARIANTS.png`` for any other set (or ``--figure``).
* ``compression``: the uniaxial compression test of Dansereau et al. (2016) §4
  (``examples/uniaxial_compression.toml``, N elements across) as
  ``benchmarks/validate.py`` runs it, with a mesh option; fault angles (active faults
  over the rupture block; damage created by the rupture) against the Mohr–Coulomb
  angle 45° − atan(μ)/2, and the imprint index of the rupture.

Options (``--variants``): ``base`` (gmsh Frontal-Delaunay: one lattice over the whole
domain); ``jitter`` (interior nodes moved by up to 0.3 × their edge length,
``domain.jitter``); ``delaunay`` (gmsh's Delaunay algorithm, ``domain.mesh_algorithm = 5``:
no domain-wide lattice direction); ``meanstress`` (``rheology.stress_correction =
"mean_stress"``: the damage correction keeps the mean normal stress); ``mean025``,
``mean050``, ``mean075``, ``mean125``, ``mean150``, ``mean200`` (the correction towards
0.25 ... 2 times the mean stress, ``stress_correction_mean_fraction``; above 1 the return
dilates);
``nu010``, ``nu045``, ``mu040``, ``mu100`` (Poisson's ratio 0.1, 0.45, friction 0.4, 1.0);
``eff`` (the envelope judges the effective stress σ/(1 − d), ``rheology.failure_stress``);
``eng`` (it judges σ/√(1 − d), the effective stress of strain-energy equivalence);
combine with ``+``, e.g. ``delaunay+meanstress``.

    python benchmarks/mesh_imprint.py cyclone --variants base jitter delaunay
    python benchmarks/mesh_imprint.py compression --n-across 40 80 --variants base jitter delaunay
    python benchmarks/mesh_imprint.py turn --variants base delaunay --jobs 2 --out benchmarks/out/mesh_imprint_floor
    python benchmarks/mesh_imprint.py report          # figure + JSON from the runs in --out
    python benchmarks/mesh_imprint.py cyclone --variants delaunay delaunay+nl16 --figure mesh_imprint_cyclone_nonlocal
    python benchmarks/mesh_imprint.py zoom --variants delaunay delaunay+nl16 --figure nonlocal_damage_zoom
    python benchmarks/mesh_imprint.py compression --n-across 20 40 --variants delaunay+explicit+nl10 --seed 0 1
    python benchmarks/mesh_imprint.py final-faults --n-across 20 40 --variants delaunay+explicit+nl10 --seed 0 1 \
        --figure compression_nonlocal_two_meshes
    python benchmarks/mesh_imprint.py final-faults --n-across 40 --variants delaunay+mean125
    python benchmarks/mesh_imprint.py final-faults --n-across 80 --variants delaunay+explicit+mean200 \
        --seed 0 1 --figure compression_explicit_dilatant    # + the stress and final damage, side by side

Runs one simulation at a time (``NUMBA_NUM_THREADS`` as set by the caller). Writes
``--out`` (default ``benchmarks/out/mesh_imprint``), ``docs/figures/mesh_imprint.json``
and ``docs/figures/mesh_imprint_cyclone.png``.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from validate import load_npz, run_finished  # noqa: E402  (load_npz: every array read once)

ROTATIONS = (0.0, 15.0, 30.0)
#: Crouzeix-Raviart velocities with the jump penalty 1 (variants vcrj1, vcrj1P)
CR_KAPPA1 = ["solver.velocity_element=crouzeix_raviart", "solver.jump_penalty=1"]
VARIANTS = {"base": [], "jitter": ["domain.jitter=0.3"], "delaunay": ["domain.mesh_algorithm=5"],
            # the loading rate (the scene pushes at 1 mm/s): half and twice as fast; the run
            # length follows, so that every variant reaches the same macroscopic strain
            "slow": ["boundary.top.v=-5e-4"], "fast": ["boundary.top.v=-2e-3"],
            # lateral confinement: the sides (tag "free") held in x
            "confined": ["boundary.free.u=0.0"],
            "meanstress": ["rheology.stress_correction=mean_stress"],
            # the associated (normal) return: the inelastic strain normal to the envelope
            "associated": ["rheology.stress_correction=associated"],
            # the explicit stepper (the basin's solver; the scene's is the implicit one), and with
            # it the Maxwell relaxation of the deviator only (rheology.relax_mean_stress = false:
            # the viscous flow of damaged ice isochoric, psi = 0, where the full relaxation
            # compacts like the origin correction). Stated before the runs (2026-11-27, 13:25 UTC,
            # N = 40, Delaunay): by the flow-rule reading ("Why the faults are steep") the explicit
            # faults lie within the spread of the implicit ones (39.2, 45.1 deg, +-5 deg), and with
            # the deviator-only relaxation the mean of the two faults turns by 3 deg or more towards
            # Mohr-Coulomb (Arthur's angle for psi = 0 is 36.3 deg; the correction still
            # compacts, so the turn is partial). Item 7 is met only if both faults lie within 10
            # deg of 27.5 deg and the plate ruptures.
            "explicit": ["solver.name=explicit"],
            # Poisson's ratio and the internal friction (the scene: nu = 0.3, mu = 0.7). Stated
            # before the runs (2026-11-27, 15:00 UTC, N = 40, Delaunay, implicit), from the
            # growth of a damage band (lagice.diagnostics.faults.damage_mode_fault_angle_deg,
            # docs/physics.md "The damage band that grows fastest"): the mean of the two faults
            # (rate, rupture block) lies within 4 deg of theta* = 1/2 acos((sin phi + sin psi)/2),
            # sin psi = -(1 - nu)/(1 + nu): nu010 48.5, nu045 42.2, mu040 47.4, mu100 42.6,
            # nu010+mu040 51.5, nu045+mu100 40.3 deg (the shipped run: 44.5 predicted, 42.2
            # measured), and the means keep the predicted order in nu and in mu. Mohr-Coulomb
            # predicts 27.5 deg whatever nu, 34.1 at mu = 0.4 and 22.5 at mu = 1.0. The reading
            # fails if any mean lies nearer Mohr-Coulomb than theta*, or if the mu040 -> mu100
            # change of the mean exceeds 8 deg (Mohr-Coulomb: 11.6 deg, theta*: 4.8 deg).
            "nu010": ["rheology.poisson=0.1"], "nu045": ["rheology.poisson=0.45"],
            "mu040": ["rheology.friction=0.4"], "mu100": ["rheology.friction=1.0"],
            "keepmean": ["rheology.relax_mean_stress=false"],
            # theta > 1 (mean125, mean150): the return towards a pressure above the element's
            # own, a dilatant flow (sin psi = (theta - 1)(1 - nu)/(1 + nu)). Stated before the
            # runs (2026-11-27, 15:06 UTC, N = 40, Delaunay): the mean of the two faults lies
            # within 4 deg of the damage band's angle, 34.6 deg (theta = 1.25) and 32.5 deg
            # (1.5), so both faults may come within the 10 deg goal; the plate is less brittle
            # than with theta = 1 (largest block drop below its 0.4 kPa), and item 7 is met only
            # if it still ruptures (a drop of at least 0.1 % of the peak) with both faults
            # within 10 deg of 27.5 deg.
            # Then (16:14 UTC, after the N = 40 runs: one wide fault at 33.6-36.3 deg): at N = 80
            # (to strain 3.5e-4) the main fault of the final damage lies within 3 deg of N = 40's
            # and within 10 deg of 27.5 deg. (Started at 16:14 to strain 3.5e-4 and stopped: at
            # 5-6 steps/s beside the other runs it needed over 80 minutes; restarted at 16:17 to
            # strain 3.3e-4, past N = 40's peak at 2.8e-4; stopped at 16:35 at step 7100 of
            # 26 400, once the second cohesion draw at N = 40 put the fault at 37-38 deg, within
            # the realisation spread of the origin path: N = 80 could no longer decide item 7.)
            # mean200 (theta = 2, psi = 32.6 deg, theta* = 28.1 deg), stated at 16:36 UTC before
            # its runs (seeds 0 and 1): the main fault of the final damage lies within 4 deg of
            # 28.1 deg in both draws (so below 32 deg, clear of the origin path's 36-39 deg),
            # and the post-peak drop is below theta = 1.25's 5-6 kPa.
            # The explicit CPU stepper with theta = 2 ("delaunay+explicit+mean200", eighteenth
            # session; N = 80 with the implicit solver runs at 4-5 steps/s here, over 4 hours),
            # stated at 17:42 UTC before its runs (N = 80, seeds 0 and 1; N = 40 alongside): the
            # main fault of the final damage lies within 10 deg of 27.5 deg (<= 37.5 deg) in both
            # N = 80 draws, and the mean of the two rate faults is at least 3 deg shallower than
            # the explicit origin path's at N = 80 (40.0 and 46.7 deg: mean 43.4 deg).
            # Then (18:28 UTC, after the theta = 2 runs: main final-damage fault 35.6 and 31.4 deg),
            # the control "delaunay+explicit --seed 1" at N = 80 (the origin path under the second
            # draw): its main final-damage fault lies at 36.4 deg or steeper (5 deg or more above
            # the theta = 2 run of the same draw).
            # Result: the prediction and the control hold. Main final-damage fault 35.6 and 31.4 deg
            # (N = 80), 30.8 and 30.5 deg (N = 40); post-peak rate faults' means 36.3 and 32.9 deg
            # (origin, same draws: 44.5 and 39.5); the control 36.6 deg. No theta = 2 plate
            # ruptures (post-peak sag 0.04-0.57 kPa; the largest block drop is the ringing before
            # any damage), and only the seed-1 plates make one straight band: item 7 not met.
            # The dilatant Maxwell viscous flow (rheology.dilatancy_angle_deg, nineteenth session;
            # explicit CPU stepper only), "delaunay+explicit+dil20" at N = 40, seed 0. Stated before
            # the run (2026-11-27, 20:05 UTC): the faults move by less than 3 deg from the explicit
            # origin run's, and the peak by less than 2 %, because this plate's viscous flow is
            # negligible (it heals before its damage nears 1: "The basin's stepper in the
            # compression test"); the dilatancy acts on the viscous flow, not on the damage event.
            # Result: the peak holds (113.0 against 112.9 kPa) and the main final-damage fault
            # (40.3 against 40.8 deg; the second 27.1 against 31.0), the rupture-block faults do
            # not (rate 0.0, 29.7 against 19.3, 32.1 deg): this plate rings without a clean rupture.
            "dil20": ["rheology.dilatancy_angle_deg=20"],
            # Damage regularised over a physical length (rheology.damage_nonlocal_radius_m,
            # lagice/solvers/nonlocal_damage.py; the load ratio averaged over the centroids within
            # R; explicit CPU stepper only). Stated before the runs (2026-11-28, 03:45 UTC), cyclone
            # disk on gmsh's Delaunay mesh ("delaunay+nl16", R = 16 km, twice the 8 km elements;
            # "delaunay" again as the control on the same code): it removes the element-scale
            # imprint if the local index of both fields (damage >= 0.5, shear rate top decile) is
            # below 0.15 at all three rotations (Delaunay: 0.24-0.31). Predicted: the damage
            # field's falls below 0.15 (its bands are then about 3 elements wide and take their
            # direction from the load), the shear rate's does not (it is one element wide where
            # the velocity jumps across a row of edges), so the rule fails; the damaged fraction
            # moves by less than 0.1. Compression ("delaunay+explicit+nl10" at N = 40: R = 10 km,
            # four elements of 2.5 km): the faults stay within 3 deg of the explicit origin
            # path's (their angle is the fastest-growing band's, which the averaging of a uniform
            # load does not change), so item 7's 10 deg goal is not met.
            # Result (2026-11-28, 04:47 UTC): the cyclone rule fails: damage's local index 0.16 /
            # 0.16 / 0.22 (Delaunay again: 0.29 / 0.30 / 0.25), the shear rate's 0.06 / 0.04 / 0.05
            # (0.30 / 0.30 / 0.31); the prediction was wrong in both fields. The maps show why the
            # indices fall: damage in parallel stripes about R apart and the shear in blobs about R
            # across, the averaging's own pattern (docs/figures/nonlocal_damage_zoom.png); the
            # damaged fraction +0.02-0.06. Compression: faults (rate) 47.0, 42.4 deg against the
            # local run's 19.3, 32.1 (final damage 42.0, 50.9 against 40.8, 31.0): the prediction
            # fails, the faults are steeper (mean 44.7, the damage band's 44.5 deg); the plate
            # ruptures on one fault pair (drop 17.3 kPa against 2.2); item 7 not met.
            # The envelope on the effective stress sigma/(1 - d) (rheology.failure_stress =
            # "effective", twenty-sixth session; cohesion C (1 - d), friction kept; implicit
            # solver and explicit CPU stepper). "delaunay+eff" at N = 20 and 40, seed 0, implicit.
            # Stated before the runs (2026-11-28, 10:26 UTC): item 7 is met only if the plate
            # ruptures (a drop of at least 0.1 % of the peak) with both rate faults of the rupture
            # block within 10 deg of 27.5 deg. Predicted: it is not: the faults stay near the
            # damage band's angle (40-47 deg), since the change weakens ice that is already
            # damaged and leaves the growth of a band in intact ice as it was; the plate ruptures
            # more sharply (its largest block drop above the origin path's 3.8 kPa at N = 40) and
            # beta at the rupture block (>= 10 boxes) is at least 0.10 (origin path: 0.07).
            "eff": ["rheology.failure_stress=effective"],
            # The envelope on sigma/sqrt(1 - d), the effective stress of strain-energy equivalence
            # (rheology.failure_stress = "energy", forty-second session; cohesion C sqrt(1 - d)).
            # "delaunay+eng" at N = 20 and 40, seed 0, implicit. Stated before the runs (2026-11-30,
            # 04:30 UTC): item 7 is met only if the plate ruptures (a drop of at least 0.1 % of the
            # peak) with both rate faults of the rupture block within 10 deg of 27.5 deg. Predicted:
            # it is not: the faults lie at 40-47 deg (the change acts on ice already damaged, not on
            # the growth of the first band in intact ice); the peak lies between the effective
            # envelope's and the nominal one's (97-117 kPa at N = 40), and the largest block drop
            # between theirs (3.8 and 62 kPa).
            # Result (2026-11-30, 04:49 UTC): item 7 not met, as predicted. Rate faults of the rupture
            # block 44.8, 44.4 deg at N = 20 and 35.4, 44.4 deg at N = 40 (one within 10 deg of 27.5);
            # final damage 9.8, 30.4 / 14.2, 27.4 deg. Peak 102 / 99 kPa (in the predicted range);
            # largest block drop 69.9 / 97.9 kPa against the effective envelope's 84 / 62 kPa: at
            # N = 40 beyond the predicted range. Wall 72 / 572 s (implicit solver).
            "eng": ["rheology.failure_stress=energy"],
            # The 8 km disk with the strength of the 5.2 km disk's elements (thirty-sixth session):
            # C_lab x sqrt(8.00 / 5.24) (the two meshes' median edges), so each element is as strong
            # as on the mesh the disk was given before 2026-11-29 and only the element size changed.
            # It separates the two causes the thirty-fifth session named for the worse imprint on
            # the 8 km disk (wider bands, weaker elements). Rule: above FLOOR_ROTATIONS.
            "str52": ["rheology.strength_lab_pa=3.46e6"],
            # the disk meshed at 5.24 km, the median edge of the thirty-fifth session's 5.2 km disk
            # (thirty-seventh session; rule above TURN_SEEDS)
            "h52": ["domain.resolution_m=5.24e3"],
            # the disk meshed at 4 km (thirty-eighth session; rule above TURN_SEEDS)
            "h40": ["domain.resolution_m=4.0e3"],
            "nl16": ["rheology.damage_nonlocal_radius_m=16e3"],
            "nl10": ["rheology.damage_nonlocal_radius_m=10e3"],
            # The same R at two resolutions (twenty-fourth session), the test that the fault does
            # not depend on the mesh: "delaunay+explicit+nl10" at N = 20 (5 km elements, R = 2
            # elements, as the flagship's R = 20 km) against N = 40 (R = 4 elements: rate faults
            # 47.0, 42.4 deg, a drop of 17.3 kPa), with the local "delaunay+explicit" at N = 20 as
            # the control, cohesion draw 0; then draw 1 at N = 20 and 40 with R = 10 km. Stated
            # before the runs (2026-11-28, 05:59 UTC): the fracture is mesh-independent if, in
            # draw 0, N = 20's rate faults over the rupture block lie within 5 deg of N = 40's
            # (pair by pair, after sorting) and the N = 20 plate ruptures (largest drop >= 10 kPa);
            # the local N = 20 control does neither (no drop >= 10 kPa, or faults more than 5 deg
            # from N = 40's nonlocal ones). Predicted: the rule holds for the angles (both near the
            # damage band's 44.5 deg) and the N = 20 plate ruptures with a peak within 10 % of
            # N = 40's 133 kPa; item 7 stays unmet (the angle is the damage band's, not
            # Mohr-Coulomb's). Draw 1 measures the spread between draws.
            # Cyclone disk, R = 11 km ("delaunay+nl11", 1.4 elements of 8 km, the ratio of the
            # flagship's nl14 run), stated at the same time: the local index of both fields below
            # 0.15 at all three rotations (the rule of nl16). Predicted: damage's index 0.15-0.25,
            # between nl16's and the local scheme's; the shear rate's below 0.15.
            "nl11": ["rheology.damage_nonlocal_radius_m=11e3"],
            # Result (06:30 UTC): the compression rule fails by 0.1 deg in draw 0: rate faults 41.9,
            # 40.6 (N = 20) against 47.0, 42.4 (N = 40), sorted pair differences 1.8 and 5.1 deg;
            # drop 10.4 kPa, peak 127 kPa (N = 40: 133). Draw 1: 41.6, 40.1 (N = 20) against 42.4,
            # 37.5 (N = 40), differences 2.6 and 0.8 deg; drops 16.2 and 14.5 kPa, peaks 128 and
            # 132 kPa. The spread between draws at N = 40 is 4.6-4.9 deg, about the N = 20 / 40
            # difference. The local N = 20 control neither ruptures (2.8 kPa) nor makes these
            # faults (0.1, 11.7 deg). Item 7 unmet: 38-47 deg against 27.5 deg.
            # Cyclone nl11 (06:34 UTC): the rule fails and the prediction too: damage's local index
            # 0.30 / 0.28 / 0.26 (the local scheme's 0.29 / 0.30 / 0.25), the shear rate's 0.22 /
            # 0.17 / 0.20; damaged fraction 0.25-0.32. At 1.4 elements the averaging leaves the
            # element-scale imprint of damage where it was (docs/figures/nonlocal_damage_zoom_r11.png).
            # Crouzeix-Raviart velocities with the jump penalty 1 (solver.velocity_element,
            # solver.jump_penalty; thirty-first session; explicit CPU stepper only), the element that
            # changed the basin's beta. Stated before the runs (2026-11-29, 04:31 UTC). Cyclone disk
            # ("delaunay+vcrj1", three rotations): the element removes the element-scale imprint if the
            # local index of both fields (damage >= 0.5, shear rate top decile) is below 0.15 at all
            # three rotations (the rule of nl16; the linear element on the same mesh: 0.29 / 0.30 / 0.25
            # and 0.30 / 0.30 / 0.31). Predicted: it does not; both within 0.1 of the linear element's,
            # since the penalty makes the element nearly conforming at the scale of a band. Compression
            # ("delaunay+explicit+vcrj1", N = 40, seed 0, against "delaunay+explicit"): item 7 is met only
            # if the plate ruptures (a block drop of at least 0.1 % of the peak) with both rate faults of
            # the rupture block, or of the post-peak phase, within 10 deg of 27.5 deg. Predicted: not met;
            # the main fault of the final damage within 5 deg of the linear element's (40.8 deg) or of
            # the damage band's angle (44.5 deg): the angle is set by the damage correction, not by the
            # velocity element; the peak within 5 % of the linear element's 113 kPa.
            "vcrj1": CR_KAPPA1,
            # Result (2026-11-29, 04:39 UTC; compression only, the cyclone runs were stopped to give
            # the cores to the runs below): the prediction fails. The plate with Crouzeix-Raviart
            # velocities peaks at 104 kPa (linear: 113; -8 %) and rings (by eye +-7 kPa, growing;
            # measured later: standard deviation 0.47 -> 5.4 kPa by quarter; linear 0.4-0.5), its
            # final damage is a dense cross-hatched network, and the damage it gains
            # after the peak runs at 26.0 and 26.4 deg to the load (linear: 51.8, 42.5; Mohr-Coulomb
            # 27.5). By the rule, item 7 is not met: the rate faults of the post-peak phase are 24.4
            # and 0.0 deg and those of the rupture block (783 blocks after the peak) 0.0 and 26.6: the
            # rate field is dominated by the ringing, as for the linear element's N = 40 run.
            # Follow-up, stated 2026-11-29 04:40 UTC before the runs (seed 0 unless noted; the linear
            # element "delaunay+explicit" beside each as the control):
            #  (a) another cohesion draw, N = 40, seed 1: the damage gained after the peak has both
            #      faults within 10 deg of 27.5 deg with Crouzeix-Raviart velocities, and neither within
            #      10 deg with linear velocities;
            #  (b) the resolution, N = 20 and N = 80 (N = 80 to strain 3e-4, past the peak at 2.2e-4 and
            #      its post-peak phase; the linear element's N = 80 run to 1e-3 is the control, its
            #      first 3e-4 the same run): the post-peak damage faults at N = 20 and at N = 80 within
            #      5 deg of N = 40's (26.0, 26.4), pair by pair after sorting;
            #  (c) the penalty, kappa = 0.1 ("vcrj", N = 40): within 5 deg of kappa = 1's, or the angle
            #      is a knob of kappa.
            # Item 7 is met only if, at N = 40 and 80, the plate ruptures with both rate faults of the
            # rupture block or of the post-peak phase within 10 deg of 27.5 deg (the rule above).
            # Predicted: (a), (b) and (c) hold for the damage faults (the velocity element, not the
            # draw, the mesh or kappa, sets the angle); item 7 stays unmet by the letter of its rule
            # at N = 40 (ringing), and at N = 80 the rate faults come within 10 deg.
            "vcrj": ["solver.velocity_element=crouzeix_raviart", "solver.jump_penalty=0.1"],
            # Result (2026-11-29, 05:22 UTC): (a), (b) and (c) fail; item 7 not met. The damage gained
            # after the peak (Crouzeix-Raviart; linear in brackets): N = 40 seed 0 26.0, 26.4 (51.8,
            # 42.5); seed 1 44.1, 43.9 (38.8, 48.3); N = 20 42.5, 27.3 (43.2, 34.7); N = 80 37.8, 48.3
            # (41.3, 51.7); kappa = 0.1 36.5, 47.6. Post-peak rate faults: 24.4, 0.0; 35.1, 26.4; 26.8,
            # 26.0; 46.9, 36.9; 36.7, 45.7. Peaks 99-107 kPa (linear 113-119). Seed 0's 26 deg was one
            # draw: right after the peak the damage grows at the damage band's angle with either
            # element. The final damage (strain 1e-3; final-faults) differs: a diffuse cross-hatched
            # network at 26.0 / 24.3 and 26.3 / 25.1 deg (seeds 0, 1; linear 40.8 / 31.0 and 38.2 /
            # 48.7), 21.7 / 29.4 at N = 20, 26.5 / 15.4 with kappa = 0.1, finder scores half the linear
            # element's, no element above d = 0.8, the stress ringing (std 5.4 kPa in seed 0's last quarter,
            # 0.93 in seed 1's); N = 80 was run to 3e-4
            # only (37.4 / 42.5). An elastic plate (cohesion 1e8 Pa, N = 20, the same element) rings by
            # 0.37 kPa, steady over 2e5 s: the growing ringing comes from the damage, not the scheme.
            # Cyclone disk (05:52 UTC): the rule fails and the prediction holds. Local index of damage >= 0.5:
            # 0.24 / 0.29 / 0.27 (linear: 0.29 / 0.30 / 0.25); of the shear rate's top decile: 0.30 / 0.27 /
            # 0.31 (0.30 / 0.30 / 0.31); damaged fraction 0.34-0.36 (0.32-0.33); 460-471 s a run.
            # neXtSIM's compressive term with the same element (thirty-third session; "P-vcrj1" of
            # physics_experiments.py, which lifts the basin's beta). Stated 2026-11-29 07:41 UTC before the
            # run: "delaunay+explicit+vcrj1P", N = 40, seed 0, against vcrj1's run. Item 7 is met only by
            # the rule above. Predicted: not met, and little change: in this 1 m plate at concentration 1,
            # P_max is 10 kPa, a fifth of the mean stress at the peak (about 50 kPa), so the term holds
            # only ice already relaxed far below the peak; the post-peak damage faults within 5 deg of
            # vcrj1's (26.0, 26.4) and the peak within 3 % of its 104 kPa.
            "vcrj1P": [*CR_KAPPA1, "rheology.max_pressure_pa=10e3", "rheology.max_pressure_thickness_exponent=1.5"],
            # Result (2026-11-29, 07:51 UTC): item 7 not met, as predicted; the prediction of little change
            # holds for the peak (104 kPa, as vcrj1's) and the final damage (a diffuse network at 26.0 /
            # 26.6 deg, finder scores 0.06, as vcrj1's 26.0 / 24.3), and fails for one post-peak damage
            # fault: 55.7 and 26.1 deg (vcrj1 26.0, 26.4). Post-peak rate faults 24.4, 0.0 (as vcrj1's);
            # rupture-block rate faults 0.0, 26.5; largest drop 12.9 kPa; 504 s.
            **{f"mean{int(round(100 * t)):03d}": ["rheology.stress_correction=mean_stress",
                                                  f"rheology.stress_correction_mean_fraction={t}"]
               for t in (0.25, 0.5, 0.75, 1.25, 1.5, 2.0)}}


def _value(v: str):
    """A --set value as the scene wants it: an integer stays an integer, true/false a boolean,
    a word a string."""
    if v in ("true", "false"):
        return v == "true"
    for kind in (int, float):
        try:
            return kind(v)
        except ValueError:
            pass
    return v


def variant_sets(name):
    return [s for part in name.split("+") for s in VARIANTS[part]]


def git_commit() -> str:
    return subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True, text=True).stdout.strip()


# -- cyclone over a disk ----------------------------------------------------------------
def made_by(run: Path) -> str:
    """The commit whose code made ``run``: what the run recorded itself (``validate.run_made_by``:
    its folder's marker, else its snapshots), else the ``RUN.commit`` file this script wrote next
    to runs on 2026-11-29 before runs recorded it; "unknown" otherwise."""
    from validate import run_made_by

    by = run_made_by(run)
    f = run.parent / f"{run.name}.commit"
    return by or (f.read_text().strip() if f.exists() else "unknown")


def cyclone_run_name(variant: str, rot: float, seed=None) -> str:
    """A cyclone run's folder name: ``_sSEED`` when the disorder seed (``run.seed``) is set
    explicitly (the rotation test's noise floor); without it the scene's own seed (12)."""
    return f"cyclone_{variant}_r{rot:g}" + ("" if seed is None else f"_s{seed}")


def run_cyclone(out: Path, variant: str, rot: float, extra_sets=(), seed=None):
    run = out / cyclone_run_name(variant, rot, seed)
    if run_finished(run):
        from validate import reuse_notice

        reuse_notice(run)   # a finished run is reused, never silently: said when its model code differs
        return run
    sets = [*variant_sets(variant), f"domain.rotate_deg={rot:g}", "run.progress=false", *extra_sets,
            *([] if seed is None else [f"run.seed={seed}"])]
    cmd = [sys.executable, "-m", "lagice.cli", "run", str(ROOT / "examples" / "imprint_cyclone_disk.toml"),
           "--out", str(run)] + (["--overwrite"] if run.exists() else [])
    for s in sets:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    print(f"mesh_imprint: run {run.name}", flush=True)
    with open(out / f"{run.name}.log", "w") as log:
        subprocess.run(cmd, check=True, stdout=log, stderr=subprocess.STDOUT, cwd=ROOT)
    print(f"mesh_imprint: {run.name} done in {time.perf_counter() - t0:.0f} s", flush=True)
    return run


def run_cyclones(out: Path, todo, jobs: int):
    """:func:`run_cyclone` for each (variant, rotation, seed) of ``todo``, ``jobs`` at a time (each one
    ``lagice run`` subprocess)."""
    from concurrent.futures import ThreadPoolExecutor

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        list(pool.map(lambda t: run_cyclone(out, t[0], t[1], seed=t[2]), todo))


def load_last(run: Path):
    import xarray as xr

    idx = json.loads((run / "snapshots" / "index.json").read_text())
    with xr.open_dataset(run / "snapshots" / idx[-1]["file"], decode_times=False) as ds:
        nodes = np.column_stack([ds["mesh_node_x"].values, ds["mesh_node_y"].values])
        tri = ds["mesh_face_nodes"].values.astype(np.int64)
        return nodes, tri, ds["damage"].values[0].copy(), ds["shear_rate"].values[0].copy()


def fracture_summaries(run: Path) -> dict:
    """The imprint summary (:func:`lagice.diagnostics.imprint.imprint_summary`) of a cyclone run's last
    snapshot for each fracture field, read once: ``damage`` (elements with d >= 0.5) and ``shear`` (the
    shear rate's top decile), each with the run's ``damaged_fraction`` (d >= 0.5)."""
    from lagice.diagnostics.imprint import imprint_summary

    nodes, tri, d, sh = load_last(run)
    out = {"damage": imprint_summary(nodes, tri, d, threshold=0.5),
           "shear": imprint_summary(nodes, tri, sh, quantile=0.9)}
    for s in out.values():
        s["damaged_fraction"] = float(np.mean(d > 0.5))
    return out


def analyse_cyclone(out: Path, variant: str):
    from lagice.diagnostics.imprint import orientation_shift_deg

    summaries = {rot: fracture_summaries(out / f"cyclone_{variant}_r{rot:g}") for rot in ROTATIONS
                 if run_finished(out / f"cyclone_{variant}_r{rot:g}")}
    res = {}
    for field in ("damage", "shear"):
        per = {rot: s[field] for rot, s in summaries.items()}
        if 0.0 in per:
            for rot, s in per.items():
                s["shift_vs_r0"] = orientation_shift_deg(per[0.0]["_angles"], per[0.0]["_weights"], s["_angles"],
                                                         s["_weights"], rotation_deg=rot)
        res[field] = per
    return res


# -- the rotation test against its noise floor -------------------------------------------
#: The rotation test with a noise floor (thirty-sixth session). Stated 2026-11-29 13:32 UTC,
#: before the runs (``mesh_imprint.py floor --variants base delaunay delaunay+str52 --seed 12 13
#: 14 15``; each variant at rotations 0, 15, 30 and 60 deg, four disorder seeds each):
#:
#: * The statistic of one pair of runs (A, B) for a rotation theta: s = corr_at_rotation -
#:   corr_at_zero of :func:`lagice.diagnostics.imprint.orientation_shift_deg` (the best of
#:   theta + 60 k against no shift). Test pairs: seed a at 0 deg against seed b at 15 and 30 deg
#:   (all 16 seed pairs, 32 values). Null pairs: seed a at 0 deg against seed b at 60 deg, the
#:   same statistic taken as if the mesh had turned by 15 and by 30 deg (32 values): a 60 deg
#:   turn changes the mesh and the disorder but not the frontal lattice's directions, so under
#:   either hypothesis its histograms should not move, and the null holds the noise of one
#:   realisation and the best-of-three bias together.
#: * The fractures follow the mesh if the median test statistic exceeds the 90th percentile of
#:   the null statistics; they do not if it lies below the null's median (between: undecided).
#: * Predicted: the frontal mesh (base) follows the mesh for the shear rate's top decile and
#:   for damage >= 0.5; Delaunay does not for either field, so the thirty-fifth session's
#:   single-realisation failure on Delaunay (15 deg: 0.92 at the rotation, -0.52 at none) was
#:   the noise of one realisation with the bias of the best of three.
#: * delaunay+str52 (the 5.2 km disk's strength): the damaged fraction (d >= 0.5) falls to
#:   0.30-0.40 (8 km strength: 0.45-0.48; 5.2 km disk: 0.31-0.36), and Delaunay's local index
#:   of damage >= 0.5 falls below 0.40 (8 km strength 0.44-0.47; 5.2 km disk 0.24-0.31), so
#:   part of the element-scale imprint at 8 km comes from over-failure, not from the size.
#:
#: Result (2026-11-29, 13:46 UTC; 48 runs of 22-25 s, two at a time; the seed-12 runs are the
#: thirty-fifth session's, bit for bit). By the rule: base damage follows the mesh (test +0.73,
#: null median -0.08, 90th pct +0.28), base shear undecided (+0.44; +0.24, +0.51), Delaunay damage
#: undecided (+0.20; +0.11, +0.55), Delaunay shear follows the mesh (+0.38; +0.04, +0.34). The
#: prediction fails for base shear and for Delaunay shear. delaunay+str52: damaged 0.37-0.43
#: (8 km strength 0.42-0.48), damage's local index 0.41-0.50 (0.42-0.49), shear follows the mesh
#: (+0.40; +0.04, +0.32): the predicted fall of the local index fails, so the element-scale imprint
#: at 8 km is not the over-failure's. Beyond the rule: two draws of the disorder on the same mesh
#: give direction histograms that correlate at a median of only 0.06-0.35 (range -0.40 to +0.83),
#: so one run's histogram is mostly its disorder; and at exactly the turn (no best of three)
#: Delaunay's shear correlates 0.07-0.09 against -0.01-0.12 at no shift: its "follows" comes
#: from the best-of-three candidates, not from the turn itself. The frontal mesh's turn shows at
#: exactly the turn too (damage +0.12 / +0.13 against -0.16 / -0.19 at no shift; shear +0.38 /
#: +0.33 against +0.20 / +0.05).
FLOOR_ROTATIONS = (0.0, 15.0, 30.0, 60.0)


def _floor_stat(a, b, theta):
    from lagice.diagnostics.imprint import orientation_shift_deg

    r = orientation_shift_deg(a["_angles"], a["_weights"], b["_angles"], b["_weights"], rotation_deg=theta)
    return r["corr_at_rotation"] - r["corr_at_zero"], r["corr_at_zero"]


def analyse_floor(out: Path, variant: str, seeds) -> dict:
    """The rotation test of the rule stated above :data:`FLOOR_ROTATIONS` on the runs of ``variant`` (every rotation of
    :data:`FLOOR_ROTATIONS` for every seed): per field, the test and null statistics, their
    medians and the null's 90th percentile, the verdict, and per run the index, the local index
    and the damaged fraction."""
    from lagice.diagnostics.imprint import orientation_shift_deg

    summaries = {(rot, sd): fracture_summaries(out / cyclone_run_name(variant, rot, sd))
                 for rot in FLOOR_ROTATIONS for sd in seeds}
    res = {}
    for field in ("damage", "shear"):
        runs = {key: s[field] for key, s in summaries.items()}
        test = [_floor_stat(runs[(0.0, a)], runs[(th, b)], th) for th in (15.0, 30.0) for a in seeds for b in seeds]
        null = [_floor_stat(runs[(0.0, a)], runs[(60.0, b)], th) for th in (15.0, 30.0) for a in seeds for b in seeds]
        # beyond the rule (added after the runs, 2026-11-29): the noise of one realisation on the same
        # mesh (seed pairs at one rotation: only the disorder differs), and each turn's correlation at no
        # shift and at exactly the turn (no best of three)
        same = [orientation_shift_deg(runs[(r, a)]["_angles"], runs[(r, a)]["_weights"], runs[(r, b)]["_angles"],
                                      runs[(r, b)]["_weights"])["corr_at_zero"]
                for r in FLOOR_ROTATIONS for i, a in enumerate(seeds) for b in seeds[i + 1:]]
        turns = {}
        for th in FLOOR_ROTATIONS[1:]:
            rr = [orientation_shift_deg(runs[(0.0, a)]["_angles"], runs[(0.0, a)]["_weights"], runs[(th, b)]["_angles"],
                                        runs[(th, b)]["_weights"], rotation_deg=th) for a in seeds for b in seeds]
            turns[f"{th:g}"] = {"corr_at_zero_median": float(np.median([x["corr_at_zero"] for x in rr])),
                                "corr_at_exact_rotation_median": float(np.median([x["corr_at_exact_rotation"]
                                                                                  for x in rr]))}
        t_med = float(np.median([x[0] for x in test]))
        n_med, n_p90 = (float(np.percentile([x[0] for x in null], q)) for q in (50, 90))
        verdict = "follows the mesh" if t_med > n_p90 else ("does not follow the mesh" if t_med < n_med
                                                            else "undecided")
        res[field] = {
            "test_stat_median": t_med, "null_stat_median": n_med, "null_stat_p90": n_p90,
            "test_corr_at_zero_median": float(np.median([x[1] for x in test])),
            "null_corr_at_zero_median": float(np.median([x[1] for x in null])),
            "n_test": len(test), "n_null": len(null), "verdict": verdict,
            "same_mesh_other_disorder_corr": {"median": float(np.median(same)), "min": float(np.min(same)),
                                              "max": float(np.max(same)), "n": len(same)},
            "turns": turns,
            "runs": {f"r{rot:g}_s{sd}": {k: s[k] for k in ("index", "local_index", "damaged_fraction", "n_segments")}
                     for (rot, sd), s in runs.items()}}
    return res


# -- the rotation test at exactly the turn, on ensembles ----------------------------------
#: The rotation test on ensembles (thirty-seventh session). Stated 2026-11-29 16:07 UTC, before the
#: runs (``mesh_imprint.py turn --variants base delaunay --jobs 2 --out
#: benchmarks/out/mesh_imprint_floor``):
#:
#: * Why a new rule: the thirty-sixth session's statistic took the best of three lattice-period
#:   candidates against one value at no shift (biased upwards on a mesh with no lattice), and its
#:   test pairs included a seed against itself, whose strength disorder (drawn per element from the
#:   node ids, ``lagice.strength.element_uniforms``) turns with the mesh. Here the ensembles at 0,
#:   15 and 30 deg use disjoint disorder seeds (:data:`TURN_SEEDS`, 12 runs each; the 0 deg set
#:   reuses the floor's seeds 12-15), so only the mesh turns between them.
#: * The statistic: :func:`lagice.diagnostics.imprint.ensemble_turn_test` on the runs' direction
#:   histograms (2.5 deg bins, 5 deg smoothing; damage >= 0.5 and the shear rate's top decile at
#:   day 3, as before): D = corr(exactly the turn) - corr(no shift) of the ensemble means, with a 90 %
#:   interval from resampling each ensemble's runs (2000 resamples, generator 0).
#: * Verdict per variant and field: "follows the mesh" if the interval lies above 0 at both turns
#:   (15 and 30 deg); "does not follow the mesh" if it lies below 0 at both; otherwise "undecided"
#:   (then the interval's upper end bounds how far the directions can turn with the mesh).
#: * Predicted: base (frontal) follows for damage and for the shear rate (the power check: last
#:   session its damage turned at exactly the turn, +0.12/+0.13 against -0.16/-0.19); Delaunay
#:   does not follow for either field, D below 0 at both turns.
#:
#: Result (2026-11-29, 16:20 UTC; 64 new runs of 20-22 s, two at a time, the 0 deg seeds 12-15 the
#: floor's): base damage follows the mesh (D +0.91 [+0.59, +1.06] at 15 deg, +1.17 [+0.62, +1.40] at
#: 30 deg), base shear undecided (+0.47 [-0.07, +0.70], +0.38 [-0.16, +0.70]); Delaunay damage
#: follows the mesh (+0.61 [+0.27, +0.74], +1.01 [+0.48, +1.12]), Delaunay shear undecided (+0.91
#: [+0.30, +1.12], +0.13 [-0.15, +0.38]). Split-half correlation of the 0 deg ensembles 0.35-0.73.
#: The prediction failed for base shear (undecided, not follows) and for Delaunay (damage follows;
#: shear turns at 15 deg and is undecided at 30 deg): on the 8 km disk the damage directions turn
#: with the mesh on gmsh's Delaunay mesh too.
#:
#: The same on the disk meshed at 5.24 km (``turn --variants delaunay+h52``; the scaled strength
#: then follows the smaller elements). Stated 2026-11-29 16:21 UTC, before the runs:
#: * the verdicts by the rule above, for both fields;
#: * "the damage directions turn less with the mesh at the finer size" if D of damage at 5.24 km is
#:   below D at 8 km at both turns and the 5.24 km verdict for damage is not "follows the mesh".
#: * Predicted: it holds (Delaunay's local index of damage was 0.24-0.31 on the 5.2 km disk of the
#:   thirty-fifth session against 0.42-0.52 at 8 km), with damage "undecided" and the shear rate
#:   "undecided" at 5.24 km.
#:
#: Result (2026-11-29, 16:42 UTC; 36 runs of 62-64 s, 26 810 elements, 4.97 km median edges): damage
#: undecided (D +0.18 [-0.17, +0.44] at 15 deg, -0.03 [-0.32, +0.32] at 30 deg; 8 km: +0.61, +1.01),
#: the shear rate does not follow the mesh (D -0.11 [-0.17, -0.05], -0.58 [-0.66, -0.50]; correlation
#: at no shift 0.98 and 0.97, split-half 0.99: a broad peak near 110 deg set by the cyclone). The
#: claim holds: the damage directions turn less with the mesh at the finer size. The prediction held
#: for damage and failed for the shear rate in the better direction ("does not follow", not
#: "undecided"). Local index 0.20-0.37 (damage) and 0.26-0.35 (shear); damaged 0.30-0.34.
#:
#: The control: the frontal mesh at 5.24 km (``turn --variants base+h52``). Stated 2026-11-29
#: 16:44 UTC, before the runs: the verdicts by the rule above; "the shear rate's independence at
#: 5.24 km comes from the size, not from Delaunay" if base+h52's shear verdict is "does not follow
#: the mesh". Predicted: it holds for the shear rate, and the frontal mesh's damage still follows
#: its lattice at 5.24 km (one lattice over the whole disk keeps pulling the one-element bands).
#:
#: Result (2026-11-29, 17:00 UTC; 36 runs of 48-57 s, 23 940 elements, 5.24 km median edges): damage
#: follows the mesh (D +1.04 [+0.84, +1.12], +1.25 [+0.95, +1.42]) and so does the shear rate (D +0.73
#: [+0.66, +0.78], +0.53 [+0.44, +0.61]; split-half 0.99): both ensembles' histograms are spikes at the
#: lattice's three directions. The claim fails: the shear rate's independence at 5.24 km is
#: Delaunay's at that size, not the size's. The prediction held for damage and failed for the shear
#: rate. Local index 0.29-0.45 (damage), 0.45-0.56 (shear); damaged 0.28-0.36.
#:
#: A finer disk: Delaunay at 4 km (``turn --variants delaunay+h40``, thirty-eighth session; the
#: scaled strength follows the smaller elements, the cyclone and the disk are unchanged). Stated
#: 2026-11-29 18:47 UTC, before the runs:
#: * the verdicts by the rule above, for both fields;
#: * "on Delaunay the damage directions stop turning with the mesh as the elements shrink" if the
#:   4 km damage verdict is "does not follow the mesh"; "the imprint falls with the size" (weaker) if
#:   D of damage at 4 km is below D at 5.24 km at both turns and its verdict is not "follows".
#: * Predicted: the shear rate does not follow (as at 5.24 km); damage is "undecided", with D below
#:   the 5.24 km values at both turns, so the weaker claim holds and the stronger one does not.
#:
#: Result (2026-11-29, 19:36 UTC; 36 runs of 149-161 s, 48 062 elements, 3.68 km median edges): damage
#: undecided (D +0.16 [+0.01, +0.27] at 15 deg, -0.23 [-0.48, +0.04] at 30 deg; 5.24 km: +0.18, -0.03), the
#: shear rate undecided (D -0.09 [-0.18, +0.01], -0.44 [-0.58, -0.29]; 5.24 km: "does not follow"). The
#: weaker claim holds (damage's D lower at both turns, its verdict not "follows"); the stronger one fails.
#: The prediction held for damage and failed for the shear rate, whose 15 deg interval reaches +0.01.
#: Split-half correlation 0.91 (damage) and 0.95 (shear); local index 0.34-0.43 (damage), 0.36-0.43
#: (shear). Figure: docs/figures/mesh_imprint_turn_h40.png (``--figure mesh_imprint_turn_h40``).
TURN_SEEDS = {0.0: tuple(range(12, 24)), 15.0: tuple(range(24, 36)), 30.0: tuple(range(36, 48))}


def analyse_turn(out: Path, variant: str) -> dict:
    """The ensemble rotation test of the rule above :data:`TURN_SEEDS` on the runs of ``variant``:
    per field and turn, :func:`lagice.diagnostics.imprint.ensemble_turn_test`, the verdict, and the
    ensembles' mean histograms (for the figure)."""
    from lagice.diagnostics.imprint import ensemble_turn_test, orientation_histogram

    summaries = {rot: [fracture_summaries(out / cyclone_run_name(variant, rot, sd)) for sd in seeds]
                 for rot, seeds in TURN_SEEDS.items()}
    res = {}
    for field in ("damage", "shear"):
        every = [s[field] for ss in summaries.values() for s in ss]
        local = [s["local_index"] for s in every]
        damaged = [s["damaged_fraction"] for s in every]
        hists = {}
        for rot, ss in summaries.items():
            hh = [orientation_histogram(s[field]["_angles"], s[field]["_weights"], 2.5) for s in ss]
            centres = hh[0][0]
            hists[rot] = np.array([h for _, h in hh])
        turns = {f"{th:g}": ensemble_turn_test(hists[0.0], hists[th], th) for th in (15.0, 30.0)}
        above = all(t["d_low"] > 0 for t in turns.values())
        below = all(t["d_high"] < 0 for t in turns.values())
        res[field] = {"turns": turns,
                      "verdict": "follows the mesh" if above else ("does not follow the mesh" if below
                                                                   else "undecided"),
                      "local_index_range": [float(min(local)), float(max(local))],
                      "damaged_fraction_range": [float(min(damaged)), float(max(damaged))],
                      "mean_histogram_deg": centres.tolist(),
                      "mean_histogram": {f"{r:g}": h.mean(axis=0).tolist() for r, h in hists.items()}}
    return res


#: the variants of the published figure ``mesh_imprint_turn.png`` (the 8 km rotation test)
TURN_FIGURE_VARIANTS = ("base", "delaunay")


def turn_figure_name(variants) -> str:
    """The default figure name of ``turn``: ``mesh_imprint_turn`` for the published variants, and
    otherwise one named after the variants, so that another set does not overwrite the published
    figure (it did once, thirty-eighth session)."""
    if sorted(variants) == sorted(TURN_FIGURE_VARIANTS):
        return "mesh_imprint_turn"
    return "mesh_imprint_turn_" + "_".join(v.replace("+", "-") for v in variants)


def figure_turn(res: dict, path: Path):
    """The ensembles' mean direction histograms at 0, 15 and 30 deg, one panel per variant and field,
    the turned ones drawn also turned back by the mesh's turn (where they would lie if the
    directions followed the mesh, they fall on the 0 deg curve)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    variants = list(res)
    fig, ax = plt.subplots(len(variants), 2, figsize=(12, 3.8 * len(variants)), squeeze=False)
    colours = {"0": "k", "15": "tab:blue", "30": "tab:red"}
    for i, v in enumerate(variants):
        for j, field in enumerate(("damage", "shear")):
            r = res[v][field]
            c = np.array(r["mean_histogram_deg"])
            a = ax[i, j]
            for rot, h in r["mean_histogram"].items():
                h = np.array(h) / (c[1] - c[0])
                a.plot(c, h, color=colours[rot], lw=1.8,
                       label=f"mesh at {rot} deg ({len(TURN_SEEDS[float(rot)])} runs)")
                if rot != "0":
                    back = np.roll(h, -int(round(float(rot) / (c[1] - c[0]))))
                    t = r["turns"][rot]
                    a.plot(c, back, color=colours[rot], lw=1.0, ls="--",
                           label=f"{rot} deg turned back; D = {t['d']:+.2f} [{t['d_low']:+.2f}, {t['d_high']:+.2f}]")
            a.set_title(f"{v}: {'damage >= 0.5' if field == 'damage' else 'shear rate, top decile'} "
                        f"- {r['verdict']}", fontsize=10)
            a.set_xlabel("fracture direction [deg]")
            a.set_ylabel("density [1/deg]")
            a.set_xlim(0, 180)
            a.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# -- uniaxial compression ---------------------------------------------------------------
def run_key(variant: str, seed: int) -> str:
    """A compression run's name in the records: the variant, with ``_sSEED`` for a seed other than 0."""
    return variant + (f"_s{seed}" if seed else "")


def run_compression(out: Path, n_across: int, variant: str, max_strain=1e-3, seed=0) -> dict:
    """validate.py's compression run (scene builder + Simulation) with the variant's mesh option."""
    from validate import analyse_compression
    from validate import run_compression as validate_compression

    tag = f"compression_N{n_across}_{run_key(variant, seed)}"
    path = out / f"{tag}.npz"
    if not path.exists():
        print(f"mesh_imprint: run {tag}", flush=True)
        sub = out / tag
        sub.mkdir(parents=True, exist_ok=True)
        overrides = dict(s.split("=", 1) for s in variant_sets(variant))
        p = validate_compression(sub, n_across, max_strain, seed,
                                 overrides={k: _value(v) for k, v in overrides.items()})
        p.replace(path)
    res = analyse_compression(path)
    z = load_npz(path)
    res["tag"] = tag
    res["imprint"] = _compression_imprint(z, res)
    return res


def _compression_imprint(z, res):
    from lagice.diagnostics import velocity_gradients
    from lagice.diagnostics.imprint import imprint_summary

    nodes, tri = z["nodes"], z["triangles"]
    k = res["rupture_block"]
    d_before = z["damage_block_end"][k - 1] if k > 0 else np.zeros(tri.shape[0])
    d_gain = np.clip(z["damage_block_end"][k].astype(float) - d_before, 0, None)
    rate = velocity_gradients(nodes, tri, z["velocity_block_mean"][k]).total_s
    out = {}
    for name, f in (("damage_final", z["damage_block_end"][-1].astype(float)), ("rate_rupture", rate),
                    ("damage_gain_rupture", d_gain)):
        s = imprint_summary(nodes, tri, f, quantile=0.9)
        out[name] = {k2: v for k2, v in s.items() if not k2.startswith("_")}
        out[name]["_angles"], out[name]["_weights"] = s["_angles"], s["_weights"]
    return out


def final_damage_faults(path: Path) -> dict:
    """The faults of a compression run's final damage (weights: damage x element area; the
    fault finder's two highest directions with their scores, the share of the damage in the
    best strip) and the principal axis of the elements with damage above 0.5 and 0.8 (its
    angle to the load and the axes' ratio: above about 5 the damage is one straight band).
    Cheap: no block analysis. Angles in degrees from the compression axis (y)."""
    from lagice.diagnostics.faults import angle_to_axis_deg, fault_orientations
    from lagice.mesh.core import signed_areas

    z = load_npz(path)
    nodes, tri = z["nodes"], z["triangles"]
    xy = nodes[tri].mean(axis=1)
    area = np.abs(signed_areas(nodes, tri))
    d = z["damage_block_end"][-1].astype(float)
    dx = float(z["width_m"]) / int(z["n_across"])
    f = fault_orientations(xy, d * area, 2 * dx)
    out = {"angles_deg": angle_to_axis_deg(f.angles_deg).tolist(), "scores": f.scores.tolist(),
           "median_trial_score": float(np.median(f.trial_scores))}
    for thr in (0.5, 0.8):
        p = xy[d > thr]
        if len(p) < 3:
            continue
        q = p - p.mean(axis=0)
        w, v = np.linalg.eigh(q.T @ q / len(q))
        out[f"axis_d{int(10 * thr)}"] = {"angle_deg": float(np.degrees(np.arctan2(abs(v[0, 1]), abs(v[1, 1])))),
                                        "aspect": float(np.sqrt(w[1] / max(w[0], 1e-30))), "n": int(len(p))}
    return out


# -- report ------------------------------------------------------------------------------
def _strip(o):
    if isinstance(o, dict):
        return {str(k): _strip(v) for k, v in o.items() if not str(k).startswith("_")}
    if isinstance(o, (list, tuple)):
        return [_strip(v) for v in o]
    if isinstance(o, (np.floating, np.integer)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    return o


def figure_compression(out: Path, n_across: int, results: dict, path: Path):
    """One column per run of ``results`` (:func:`run_key` -> :func:`run_compression`'s result): the
    macroscopic stress (the post-peak phase shaded), the total deformation rate summed over the
    post-peak phase (log, relative to its 99.5th percentile), and the damage at the end of the run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(3, len(results), figsize=(5.2 * len(results), 13.5), squeeze=False)
    for j, (v, r) in enumerate(results.items()):
        z = load_npz(out / f"compression_N{n_across}_{v}.npz")
        s, dt, block = z["stress_pa"], float(z["dt_s"]), int(z["block_steps"])
        nodes, tri = z["nodes"] / 1e3, z["triangles"]
        b0, b1 = r["post_peak"]["blocks"]
        rate = r["_plot"]["post_peak_rate"]
        ax[0, j].plot((np.arange(s.size) + 1) * dt / 1e3, s / 1e3, lw=0.8)
        ax[0, j].axvspan(b0 * block * dt / 1e3, b1 * block * dt / 1e3, color="0.85")
        ax[0, j].set(xlabel="time (ks)", ylabel="compressive stress (kPa)")
        ax[0, j].set_title(f"N = {n_across}, {v}", fontsize=9)
        pp = r["post_peak"]["fault_angles_damage_deg"] or []
        ref = max(float(np.percentile(rate, 99.5)), 1e-300)
        ax[1, j].tripcolor(nodes[:, 0], nodes[:, 1], tri, cmap="magma", vmin=-2, vmax=0,
                           facecolors=np.log10(np.clip(rate / ref, 1e-2, 1.0)))
        ax[1, j].set(aspect="equal", xlabel="x (km)")
        ax[1, j].set_title("post-peak rate, log10 of rate / its 99.5th pct", fontsize=9)
        tp = ax[2, j].tripcolor(nodes[:, 0], nodes[:, 1], tri, facecolors=z["damage_block_end"][-1].astype(float),
                                cmap="viridis", vmin=0, vmax=1)
        ax[2, j].set(aspect="equal", xlabel="x (km)")
        ax[2, j].set_title("damage at the end; post-peak bands " + ", ".join(f"{a:.0f}°" for a in pp), fontsize=9)
    fig.colorbar(tp, ax=ax[2, :].tolist(), shrink=0.6, label="damage")
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


def figure_final_damage(out: Path, runs: list, path: Path):
    """One column per run (``(n_across, key)`` of a compression record in ``out``): the
    macroscopic stress against the strain, and the damage at the end with the final-damage
    faults of :func:`final_damage_faults` in the title. Cheap (no block analysis)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(2, len(runs), figsize=(3.6 * len(runs), 9.0), squeeze=False,
                           gridspec_kw={"height_ratios": [1, 2.2], "wspace": 0.5})
    for j, (n, key) in enumerate(runs):
        p = out / f"compression_N{n}_{key}.npz"
        z = load_npz(p)
        s, dt = z["stress_pa"], float(z["dt_s"])
        strain = (np.arange(s.size) + 1) * dt * float(z["push_speed_m_s"]) / float(z["length_m"])
        ax[0, j].plot(strain * 1e3, s / 1e3, lw=0.8)
        ax[0, j].set(xlabel="strain (10$^{-3}$)", ylabel="compressive stress (kPa)")
        ax[0, j].set_title(f"N = {n}, {key}", fontsize=8)
        nodes, tri = z["nodes"] / 1e3, z["triangles"]
        r = final_damage_faults(p)
        tp = ax[1, j].tripcolor(nodes[:, 0], nodes[:, 1], tri, facecolors=z["damage_block_end"][-1].astype(float),
                                cmap="viridis", vmin=0, vmax=1)
        ax[1, j].set(aspect="equal", xlabel="x (km)")
        a8 = r.get("axis_d8")   # absent where no element passed d = 0.8
        ax[1, j].set_title("final damage; faults " + ", ".join(f"{a:.0f}°" for a in r["angles_deg"])
                           + ("\nno element with d > 0.8" if a8 is None else
                              f"\naxis of d > 0.8: {a8['angle_deg']:.0f}° ({a8['aspect']:.0f} : 1)"), fontsize=8)
    fig.colorbar(tp, ax=ax[1, :].tolist(), shrink=0.6, label="damage")
    fig.savefig(path, dpi=80)
    print(f"wrote {path}")


def figure_zoom(out: Path, variants, path: Path, box_km=(-250.0, -50.0, -150.0, 50.0)):
    """Damage and the shear rate at day 3 (mesh not rotated) in a 200 km box of the disk's
    western half, one row per variant: the element-scale pattern the whole-disk maps hide."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri

    fig, ax = plt.subplots(len(variants), 2, figsize=(10, 5 * len(variants)), squeeze=False)
    for i, v in enumerate(variants):
        nodes, tri, d, sh = load_last(out / f"cyclone_{v}_r0")
        t = mtri.Triangulation(nodes[:, 0] / 1e3, nodes[:, 1] / 1e3, tri)
        im0 = ax[i, 0].tripcolor(t, d, vmin=0, vmax=1, cmap="magma_r")
        im1 = ax[i, 1].tripcolor(t, np.log10(np.maximum(sh, 1e-10)), vmin=-9.0, vmax=-5.0, cmap="viridis")
        ax[i, 0].set_title(f"{v}: damage, day 3", fontsize=10)
        ax[i, 1].set_title(f"{v}: log10 shear rate [s-1], day 3", fontsize=10)
        for a, im in ((ax[i, 0], im0), (ax[i, 1], im1)):
            a.set_xlim(*box_km[:2])
            a.set_ylim(*box_km[2:])
            a.set_aspect("equal")
            a.set_xlabel("x [km]")
            fig.colorbar(im, ax=a, shrink=0.8)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def figure_cyclone(out: Path, variants, path: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.tri as mtri

    from lagice.diagnostics.imprint import orientation_histogram

    fig, ax = plt.subplots(len(variants), 4, figsize=(17, 4.2 * len(variants)), squeeze=False)
    for i, v in enumerate(variants):
        hist_ax = ax[i, 3]
        for j, rot in enumerate(ROTATIONS):
            run = out / f"cyclone_{v}_r{rot:g}"
            if not run_finished(run):
                continue
            nodes, tri, d, _ = load_last(run)
            t = mtri.Triangulation(nodes[:, 0] / 1e3, nodes[:, 1] / 1e3, tri)
            ax[i, j].tripcolor(t, d, vmin=0, vmax=1, cmap="magma_r")
            ax[i, j].set_aspect("equal")
            ax[i, j].set_title(f"{v}: mesh rotated {rot:g}°, damage day 3", fontsize=9)
            ax[i, j].set_xticks([])
            ax[i, j].set_yticks([])
            from lagice.diagnostics.imprint import imprint_summary

            s = imprint_summary(nodes, tri, d, threshold=0.5)
            c, h = orientation_histogram(s["_angles"], s["_weights"])
            hist_ax.plot(c, h, label=f"{rot:g}° (index {s['index']:.2f})")
            for md in s["mesh_directions_deg"]:
                hist_ax.axvline(md, color=hist_ax.lines[-1].get_color(), ls=":", lw=0.8)
        hist_ax.set_xlabel("fracture direction (deg from x)")
        hist_ax.set_ylabel("fraction")
        hist_ax.set_title(f"{v}: damage-band directions (dotted: mesh directions)", fontsize=9)
        hist_ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=("cyclone", "floor", "turn", "compression", "report", "final-faults", "zoom"))
    ap.add_argument("--variants", nargs="+", default=["base"])
    ap.add_argument("--n-across", type=int, nargs="+", default=[40])
    ap.add_argument("--max-strain", type=float, default=1e-3)
    ap.add_argument("--seed", type=int, nargs="+", default=[0],
                    help="compression, final-faults: run.seed (the cohesion disorder), one run per seed; "
                         "results keyed VARIANT_sSEED when not 0; floor: the disorder seeds (at least 2)")
    ap.add_argument("--jobs", type=int, default=1, help="floor, turn: runs at a time (each one lagice subprocess)")
    ap.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "out" / "mesh_imprint")
    ap.add_argument("--fig-dir", type=Path, default=ROOT / "docs" / "figures")
    ap.add_argument("--figure", default=None, metavar="NAME",
                    help="cyclone: FIG_DIR/NAME.png instead of mesh_imprint_cyclone.png; turn: instead of "
                         "mesh_imprint_turn.png (variants base and delaunay) or mesh_imprint_turn_VARIANTS.png; "
                         "compression: also FIG_DIR/NAME.png, the variants side by side (stress, rate, damage); "
                         "final-faults: the stress and the final damage of each run")
    args = ap.parse_args(argv)
    out = args.out.resolve()
    out.mkdir(parents=True, exist_ok=True)
    args.fig_dir.mkdir(parents=True, exist_ok=True)   # before any figure is drawn into it
    js = args.fig_dir / "mesh_imprint.json"
    allres = json.loads(js.read_text()) if js.exists() else {}
    if args.what == "cyclone":
        for v in args.variants:
            made = False   # whether any rotation was run now (not only analysed again)
            for rot in ROTATIONS:
                made |= not run_finished(out / f"cyclone_{v}_r{rot:g}")
                run_cyclone(out, v, rot)
            res = analyse_cyclone(out, v)
            allres.setdefault("cyclone", {})[v] = _strip(res)
            prov = allres.setdefault("provenance", {})
            if made or f"cyclone/{v}" not in prov:   # the commit(s) whose code made the runs
                by = sorted({made_by(out / f"cyclone_{v}_r{rot:g}") for rot in ROTATIONS})
                if len(by) > 1:
                    print(f"mesh_imprint: WARNING: the rotations of {v} were made by different code ({', '.join(by)}): "
                          f"the rotation test compares meshes and code at once", flush=True)
                prov[f"cyclone/{v}"] = {"git_commit": by[0] if len(by) == 1 else by, "date": time.strftime("%Y-%m-%d")}
            for field, per in res.items():
                for rot, s in per.items():
                    sh = s.get("shift_vs_r0", {})
                    print(f"  cyclone {v:10s} {field:7s} rot {rot:4g}: index {s['index']:.3f}  F {s['fraction']:.3f} "
                          f"(chance {s['chance']:.2f})  n {s['n_segments']}  shift vs 0°: "
                          f"{sh.get('shift_deg', float('nan')):.1f}° (corr at 0°: "
                          f"{sh.get('corr_at_zero', float('nan')):.2f}, at the rotation: "
                          f"{sh.get('corr_at_rotation', float('nan')):.2f})  damaged {s['damaged_fraction']:.2f}")
        figure_cyclone(out, args.variants, args.fig_dir / f"{args.figure or 'mesh_imprint_cyclone'}.png")
    elif args.what == "floor":   # the rotation test against its noise floor (the rule above FLOOR_ROTATIONS)
        if len(args.seed) < 2:
            ap.error("floor needs at least two --seed values (the noise floor compares realisations)")
        todo = [(v, rot, sd) for v in args.variants for sd in args.seed for rot in FLOOR_ROTATIONS]
        run_cyclones(out, todo, args.jobs)
        for v in args.variants:
            by = sorted({made_by(out / cyclone_run_name(v, rot, sd)) for rot in FLOOR_ROTATIONS for sd in args.seed})
            if len(by) > 1:
                print(f"mesh_imprint: WARNING: the runs of {v} were made by different code ({', '.join(by)})",
                      flush=True)
            res = analyse_floor(out, v, args.seed)
            allres.setdefault("rotation_floor", {})[v] = _strip(res) | {
                "seeds": list(args.seed), "rotations_deg": list(FLOOR_ROTATIONS),
                "git_commit": by[0] if len(by) == 1 else by, "date": time.strftime("%Y-%m-%d")}
            for field, r in res.items():
                runs = r["runs"].values()
                print(f"  floor {v:16s} {field:7s}: test statistic median {r['test_stat_median']:+.2f}, null median "
                      f"{r['null_stat_median']:+.2f}, null 90th pct {r['null_stat_p90']:+.2f} -> {r['verdict']}; "
                      f"corr at no shift: test {r['test_corr_at_zero_median']:.2f}, null "
                      f"{r['null_corr_at_zero_median']:.2f}; local index "
                      f"{min(x['local_index'] for x in runs):.2f}-{max(x['local_index'] for x in runs):.2f}; "
                      f"damaged {min(x['damaged_fraction'] for x in runs):.2f}-"
                      f"{max(x['damaged_fraction'] for x in runs):.2f}", flush=True)
                sm = r["same_mesh_other_disorder_corr"]
                turns = "; ".join(f"turned {th} deg: corr at no shift {t['corr_at_zero_median']:+.2f}, at exactly "
                                  f"{th} deg {t['corr_at_exact_rotation_median']:+.2f}" for th, t in r["turns"].items())
                print(f"      same mesh, other disorder: corr {sm['median']:+.2f} [{sm['min']:+.2f}, "
                      f"{sm['max']:+.2f}]; {turns}", flush=True)
    elif args.what == "turn":   # the rotation test on ensembles (the rule above TURN_SEEDS)
        run_cyclones(out, [(v, rot, sd) for v in args.variants for rot, seeds in TURN_SEEDS.items() for sd in seeds],
                     args.jobs)
        res = {}
        for v in args.variants:
            by = sorted({made_by(out / cyclone_run_name(v, rot, sd)) for rot, seeds in TURN_SEEDS.items()
                         for sd in seeds})
            res[v] = analyse_turn(out, v)
            allres.setdefault("rotation_turn", {})[v] = _strip(res[v]) | {
                "seeds": {f"{r:g}": list(sds) for r, sds in TURN_SEEDS.items()},
                "git_commit": by[0] if len(by) == 1 else by, "date": time.strftime("%Y-%m-%d")}
            for field, r in res[v].items():
                tt = "; ".join(f"turned {th} deg: corr at no shift {t['corr_at_zero']:+.2f}, at the turn "
                               f"{t['corr_at_exact_rotation']:+.2f}, D {t['d']:+.2f} [{t['d_low']:+.2f}, "
                               f"{t['d_high']:+.2f}]" for th, t in r["turns"].items())
                print(f"  turn {v:10s} {field:7s}: {r['verdict']}; {tt}; split-half corr of the 0 deg ensemble "
                      f"{r['turns']['15']['split_half_corr_ref']:+.2f}; local index "
                      f"{r['local_index_range'][0]:.2f}-{r['local_index_range'][1]:.2f}", flush=True)
        figure_turn(res, args.fig_dir / f"{args.figure or turn_figure_name(args.variants)}.png")
    elif args.what == "compression":
        for n in args.n_across:
            results = {}
            for v, sd in ((v, sd) for v in args.variants for sd in args.seed):
                key = run_key(v, sd)
                r = results[key] = run_compression(out, n, v, args.max_strain, sd)
                im = r["imprint"]["rate_rupture"]
                if not r["ruptured"]:
                    print(f"  compression N={n} {key:10s}: NO RUPTURE (largest stress drop {r['rupture_drop_kpa']:.3f} "
                          f"kPa, below {100 * r['rupture_min_drop_fraction']:g} % of the peak, or no damage made in "
                          f"that block) up to strain {args.max_strain:g}; peak {r['peak_stress_kpa']:.0f} kPa",
                          flush=True)
                print(f"  compression N={n} {key:10s}: fault angles (rate) "
                      f"{[round(a, 1) for a in (r['fault_angles_rate_deg'] or [])]} (damage) "
                      f"{[round(a, 1) for a in (r['fault_angles_damage_deg'] or [])]} MC "
                      f"{r['mohr_coulomb_angle_deg']:.1f}, damage band "
                      f"{r['damage_mode_angle_deg'] or float('nan'):.1f}; "
                      f"imprint index (rate) {im['index']:.3f}; peak "
                      f"{r['peak_stress_kpa']:.0f} kPa; wall {r['wall_s']:.0f} s", flush=True)
                pp = r["post_peak"]
                print(f"      largest drop {r['rupture_drop_kpa']:.2f} kPa, {r['rupture_blocks_after_peak']} blocks "
                      f"after the peak; post-peak phase (blocks {pp['blocks'][0]}-{pp['blocks'][1]}, drop "
                      f"{pp['stress_drop_kpa']:.2f} kPa): faults (rate) "
                      f"{[round(a, 1) for a in (pp['fault_angles_rate_deg'] or [])]} (damage gained) "
                      f"{[round(a, 1) for a in (pp['fault_angles_damage_deg'] or [])]}", flush=True)
                allres.setdefault("compression", {}).setdefault(f"N{n}", {})[key] = _strip(
                    {k: r[k] for k in ("fault_angles_rate_deg", "fault_angles_damage_deg", "fault_directions_rate_deg",
                                       "mohr_coulomb_angle_deg", "damage_mode_angle_deg", "peak_stress_kpa",
                                       "rupture_time_s", "wall_s",
                                       "imprint", "ruptured", "rupture_drop_kpa", "rupture_blocks_after_peak",
                                       "post_peak")} | {"git_commit": git_commit()})
            if args.figure:
                figure_compression(out, n, results, args.fig_dir / f"{args.figure}.png")
    elif args.what == "final-faults":   # the final damage's faults of runs already made (no block analysis)
        keys = [(n, run_key(v, sd)) for n in args.n_across for v in args.variants for sd in args.seed]
        for n, key in keys:
            path = out / f"compression_N{n}_{key}.npz"
            r = final_damage_faults(path)
            axes = "; ".join(f"damage > 0.{k[-1]}: axis {a['angle_deg']:.1f} deg, aspect {a['aspect']:.1f}"
                             for k, a in r.items() if k.startswith("axis_"))
            print(f"  N={n} {key:24s} final damage faults {[round(a, 1) for a in r['angles_deg']]} scores "
                  f"{[round(x, 3) for x in r['scores']]} (median trial {r['median_trial_score']:.3f}); {axes}")
            entry = allres.setdefault("compression", {}).setdefault(f"N{n}", {}).setdefault(key, {})
            entry["final_damage_faults"] = r
        if args.figure:
            figure_final_damage(out, keys, args.fig_dir / f"{args.figure}.png")
    elif args.what == "zoom":   # the cyclone runs already made, unrotated, in a 200 km box
        figure_zoom(out, args.variants, args.fig_dir / f"{args.figure or 'mesh_imprint_zoom'}.png")
        return
    else:
        figure_cyclone(out, [v for v in allres.get("cyclone", {})], args.fig_dir / "mesh_imprint_cyclone.png")
    js.write_text(json.dumps(allres, indent=1))
    print(f"wrote {js}")


if __name__ == "__main__":
    main()
