"""β against the element size on a test bed a hundred times cheaper than the basin (issue 12).

In the basin, the families whose floes are held by a sparse network of weak bands lose 0.02–0.07 of β
from 20 to 10 km, at the neXtSIM strength law and at the same cohesion in pascals alike, and the cause
is not found (docs/physics.md §5). A basin month at 10 km costs 6–7 minutes and its β moves by about
0.03 with the weather and the box grid, so every test of a cause has cost hours. This script asks the
same question of one cyclone over a closed disk 500 km in radius (``examples/imprint_cyclone_disk.toml``
on ``data_stubs/disk_500km.geojson``): pristine 1 m ice, no healing, no thermodynamics, no remeshing, no
spin-up, 3 days. A run takes 10 s at 20 km and about 3 min at 5 km on one core.

Families (``--family``): ``lead``, the strong-floe lead of the basin (the effective envelope, damage cap
0.97, C_lab 22.4 MPa: docs/physics.md §4, "Strong floes in a weak network"); ``shipped``, the flagship's
nominal envelope at neXtSIM's strength (C_lab 2.80 MPa in lagice's form). Strength (``--law``):
``same_pa``, the lab cohesion times √(Δx/20 km), so that every mesh has the 20 km mesh's cohesion in
pascals; ``scaled``, neXtSIM's law as shipped (a mesh √2 finer is √2 stronger).

Statistic: one Lagrangian window over the cyclone's passage, days 1–3 (the ice does not move before
day 1), on the elements at least 100 km from the coast, with the validation's estimator
(:func:`lagice.diagnostics.windows.window_summary`). β is fitted on the box widths every mesh resolves,
25–220 km (``COMMON_FIT_M``; widths with at least 10 boxes, in practice 26–150 km: two to three
widths per mesh), and also on each mesh's own widths.

Rule RD (written at 21:57 UTC on 2026-11-30, before the runs of this script; a preview of three seeds on
the 300 km disk was seen first: per-day β on each mesh's own widths 0.17–0.39 at 20 km, 0.06–0.15 at
10 km, 0.07–0.17 at 5 km). Family ``lead``, law ``same_pa``, meshes 20, 14, 10, 7 and 5 km, seeds 12–17.
  (R1) The disk reproduces the basin's fall if the median β (common widths) at 10 km is at least 0.02
       below the median at 20 km.
  (R2) β has converged by 10 km if the medians at 7 and 5 km both lie within 0.02 of the 10 km median;
       it keeps falling if the 5 km median is at least 0.02 below the 10 km one.
  Predicted: R1 holds, by 0.05–0.15; R2 says converged. If so, the basin's fall would be the 20 km
  mesh's coarseness in this family, and its 10 km statistics the converged model's.

  Result (22:09 UTC): R1 holds, by 0.043 (20 km 0.185, 10 km 0.142); R2 is neither: 7 km 0.137 and 5 km
  0.187, back at the 20 km value, with 90 % intervals of the medians 0.05–0.16 wide. One 20 km run (seed 12)
  had been made as a test of this script a minute before the rule was written. On each mesh's own widths
  the medians fall 0.166, 0.145, 0.121, 0.103, 0.103: the finest octave is flat on every mesh.

Rule RD2 (written at 22:12 UTC, before its runs; the pooled figures of the first six seeds were first
printed when the report code was tested, after the text of the rule). Six more seeds (18–23) for
``lead same_pa``, and the control ``shipped same_pa`` (seeds 12–23). The report adds the pooled curve per
mesh (every box of every seed, :func:`lagice.diagnostics.scaling.pooled_spatial_scaling`), its β on the
common widths, and its slope per octave.
  (a) Over 12 seeds the lead's common-width β has no trend with the element if the pooled β at 20, 10 and
      5 km lie within 0.03 of each other; it falls if the 5 km pooled β is at least 0.03 below 20 km's.
  (b) The first octave (Δx to 2Δx) of the pooled curve is flatter than the octave from 4Δx to 8Δx on
      every mesh, in both families (the element scale's own flattening).
  Predicted: (a) no trend; (b) holds; the shipped family's β is 0.03–0.09 on every mesh, as in the basin.

Rule RD3 (written at 22:41 UTC, before the 20 km runs were made again; the 10 km curve below had been
computed): the same question in the basin, for the lead over its eight months of weather at 20 km and
10 km (neXtSIM's scaled strength, as in rule R10; ``physics_experiments.py`` runs
``B20-hthick-eff-C8-cap97-m20[-wSEED]`` and ``F10-hthick-eff-C8-cap97[-wSEED]``). ``basin`` pools every
3-day window of a group (from day 1, 100 km from the coast) and fits β on the widths both meshes resolve,
20–120 km (``BASIN_COMMON_FIT_M``; three widths on each mesh). The 10 km pooled curve (72 windows) was
seen first: slopes 0.185, 0.144, 0.139 and 0.129 per octave from 6 to 93 km, not flat at the element.
  (c) The basin's fall survives on the common widths if the 20 km pooled β there exceeds the 10 km one
      by at least 0.02.
  Predicted: (c) holds (20 km 0.16–0.19, 10 km 0.13–0.14): unlike one storm on a pristine disk, the
  basin's fall is not the estimator's reach into the element's octave.

  Result (22:57 UTC): (c) holds, as predicted. On 24–93 km (the two meshes' box widths coincide) the pooled
  β is 0.172 at 20 km and 0.134 at 10 km; month by month it is lower at 10 km in 6 of 8 months (median
  −0.039). By octave: 24–47 km 0.135 and 0.139, 47–93 km 0.207 and 0.129.

Rule RD4 (written at 22:59 UTC, before its runs). The basin's months use neXtSIM's scaled strength (a mesh √2
finer is √2 stronger), the disk's runs above the same cohesion in pascals. ``lead scaled`` on the disk,
seeds 12–23, 20 to 5 km.
  (d) The strength law alone makes a fall on the disk if the pooled β on the common widths at 5 km is at
      least 0.03 below the 20 km one.
  Predicted: the disk breaks less on finer meshes (the rate falls by ×0.5 or more from 20 to 5 km), and
  (d) holds.
  Result (23:25 UTC): (d) fails; the rate falls ×0.16 from 20 to 5 km (0.0055 → 0.0009 per day), but the
  pooled β on the common widths is 0.195, 0.232, 0.089, 0.265 and 0.281 at 20, 14, 10, 7 and 5 km: highest
  where the pack nearly locks (7, 5 km), lowest at 10 km, where the storm fails the pack diffusely in all
  twelve draws (half the shear in 5–18 % of the area).

Rule RD5 (written at 23:58 UTC, before its runs; one 4-day run at 20 km was made first to time the scene, and
none of its statistics was looked at). One storm on pristine ice lacks the basin's time-dependent pieces: weeks
of weather with many storms, thermodynamics, neXtSIM's healing, mesh motion and remeshing. Stage ``month`` runs
``examples/winter_disk.toml`` (all of them, over the same disk of uniform 1 m ice, from no spin-up; no island,
no thick-and-thin pack) with the eight months' wind seeds (2026–2033), family ``lead``, law ``same_pa``, at 20
and 10 km. ``report --stage month`` pools every 3-day window from day 1 (100 km from the coast), as ``basin``.
  (e) The month's pieces make the fall if the pooled β on 20–120 km (``BASIN_COMMON_FIT_M``) at 10 km is at
      least 0.02 below the 20 km one; (f) β on those widths is lower at 10 km in at least 6 of the 8 months.
  Predicted: (e) and (f) hold, with a fall of 0.02–0.05 that sits in the widest octave, as in the basin. If
  they fail, the fall needs the basin's geometry or its spun-up, thick-and-thin start.

  Result (00:25 UTC): (e) fails, by 0.0015: the pooled β on 20–120 km is 0.145 at 20 km and 0.126 at 10 km (a
  fall of 0.018); (f) holds: β is lower at 10 km in 7 of 8 months (median −0.015). By octave the fall sits in
  the widest one (52–104 km: 0.143 against 0.104), as in the basin. Looked at after the rule was judged (no
  rule): in the first window (days 1–4) β is higher at 10 km (0.149 against 0.138), in the later ones lower
  (0.124 against 0.144), and at 10 km it falls through the month (0.149 in days 1–4, 0.099 in days 25–28).
  Maps show the bands cutting the pack into smaller floes at 10 km. The band length per area (elements with
  damage > 0.9, 100 km from the coast, each as long as √area; median over the months) is 0.0142 and 0.0186
  km⁻¹ on day 4, 0.0289 and 0.0478 on day 28 (20 and 10 km): ×1.3 growing to ×1.65; at 20 km it stops
  growing after day 16, at 10 km it does not.

Rule RD6 (written at 00:27 UTC, before its runs). A reading of RD5: at the same cohesion in pascals a band one
element wide costs an energy proportional to Δx (the elastic energy density released at failure, ∝ σc²/E,
times the band's width), so the same weather buys more band length on a finer mesh, and over weeks of breaking
and healing the finer mesh cuts the pack into smaller floes (the crack band argument of Bažant and Oh 1983).
neXtSIM's law σc ∝ Δx^(−1/2) keeps that energy per band length the same on every mesh. Stage ``month`` with
law ``scaled`` (family ``lead``, the same eight wind seeds, 20 and 10 km; at 20 km the cohesion is the same as
``same_pa``'s, so those runs must repeat RD5's bit for bit).
  (g) The band length per area on day 28 at 10 km lies within ×0.8–1.25 of the 20 km one (RD5: ×1.65).
  (h) The pooled β on 20–120 km falls from 20 to 10 km by less than 0.02, and is lower at 10 km in at most 5
      of the 8 months.
  Predicted: (g) and (h) hold. Then the basin's fall under the same law (RD3: 0.038) would need the basin's
  geometry or its spun-up, thick-and-thin start; if (g) holds and (h) fails, band length is not what sets
  β's fall.

  Result (00:52 UTC): both fail; both predictions were wrong. (g): the band length per area on day 28 is 1.35
  times the 20 km one (0.0390 against 0.0289 km⁻¹; ×1.65 at the same cohesion). (h): the pooled β on 20–120 km
  falls by 0.020 (0.145 → 0.124), lower at 10 km in 7 of 8 months (median −0.021), in the widest octave
  (52–103 km: 0.095). The 20 km months repeat RD5's bit for bit (every field of the last snapshots of three
  months compared). At 10 km the first window's β is again higher than 20 km's (0.173 against 0.138), and the
  later ones lower. So on the disk the month's pieces make half the basin's fall under either law; the law
  changes the extra band length (×1.65 → ×1.35) and not the fall of β.

Rule RD7 (written at 00:55 UTC, before its analysis; no new runs). Is β set by how far the pack is cut into
floes, with the mesh only changing how fast? Every window of RD5's and RD6's months (2 laws × 2 meshes × 8
months × 9 windows) is labelled by the band length per area on its first day, and the windows of each mesh
are pooled by bin of band length (below 0.02, 0.02–0.03, 0.03–0.04, 0.04 km⁻¹ and above), β on 20–120 km.
  (k) Fragmentation sets β if, in every bin with at least 8 windows on both meshes, the 20 and 10 km β lie
      within 0.02 of each other, and on each mesh β is at least 0.03 lower in its most cut bin than in its
      least cut one (bins with at least 8 windows).
  Predicted: (k) holds.

Rule RD8 (written at 00:55 UTC, before its runs). Healing is the time-dependent piece whose cycle of mending
and breaking again could cut the finer mesh further. Stage ``month``, variant ``noheal`` (``healing.law =
none``), family ``lead``, law ``same_pa``, the eight wind seeds, 20 and 10 km.
  (m) Healing is not needed for the fall if the pooled β on 20–120 km falls from 20 to 10 km by at least 0.02
      and is lower at 10 km in at least 6 of 8 months (RD5's (e) and (f) on these runs).
  Predicted: (m) holds; the band length per area on day 28 is at least 1.25 times the 20 km one.

  Result (01:21 UTC): (m) fails; the prediction was wrong for β and right for the band length. Without healing
  the pooled β on 20–120 km falls from 20 to 10 km by 0.010 (0.131 → 0.121), lower at 10 km in 5 of 8 months
  (median −0.010), while the band length per area on day 28 is 1.57 times the 20 km one (0.0431 against
  0.0274). β now falls through the month on both meshes (days 1–4 to days 25–28: 0.168 → 0.094 at 20 km,
  0.166 → 0.102 at 10 km) and the rate rises (window medians 0.0235 and 0.0201 per day, against 0.0165 and
  0.0149 with healing). The band length hardly moves with healing (day 28: 0.0274 against 0.0289 at 20 km,
  0.0431 against 0.0478 at 10 km). So healing is what lets the 20 km mesh keep its β through the month, and
  half of the fall between the meshes goes without it; what healing changes is not how far the bands cut.
  How firmly (computed after the verdict, no rule): the month-by-month fall (10 km less 20 km, mean of the 8
  months, 90 % interval from resampling the months) is −0.022 [−0.036, −0.009] with healing (RD5), −0.024
  [−0.038, −0.011] under the scaled law (RD6) and −0.009 [−0.017, 0.000] without healing; paired by month,
  healing adds −0.013 [−0.027, +0.001]. So healing's part is suggested by these eight months, not shown.

Rule RD9 (written at 01:23 UTC, before its runs). The basin's months start from a 14-day spin-up, so every one
of their windows comes after two weeks of breaking; on the disk the first window, on pristine ice, has a higher
β at 10 km than at 20 km, and the later ones a lower. Variant ``spun``: each month starts from the end of a
14-day run of the same scene, mesh and strength from pristine ice (wind seed 2025 from 1 January, as the
basin's spin-up; the strength disorder is run.seed 2026's, as in the months), family ``lead``, law ``same_pa``,
the eight wind seeds, 20 and 10 km.
  (n) The spun-up start adds to the fall if the pooled β on 20–120 km falls from 20 to 10 km by at least 0.03
      and is lower at 10 km in at least 6 of the 8 months.
  Predicted: (n) holds, with a fall of 0.03–0.04 (the basin's 0.038): the rest of the basin's fall would be
  its start, not its coast.

  Result (01:58 UTC): (n) fails; the prediction was wrong. From the spun-up start the pooled β on 20–120 km
  falls by 0.018 (0.139 → 0.120), as from pristine ice, but now lower at 10 km in all 8 months (median −0.014;
  month by month −0.017, 90 % interval −0.023 to −0.011), and from the first window on (days 1–4: 0.116
  against 0.158). The band length per area is 1.9 times the 20 km one from day 4 (0.043 against 0.023 km⁻¹)
  to day 28 (0.053 against 0.027). So the spin-up makes the fall steadier, not larger. The basin's own fall,
  month by month, is −0.034 (90 % interval −0.060 to −0.006; RD3's months): not firmly larger than the disk's.

Rule RD10 (written at 02:20 UTC, 1 December, before its runs). The basin's months start from a spin-up of a
thick-and-thin pack (thickness 1.1–1.85 m and concentration 0.87–0.97 varying over hundreds of kilometres), the
disk's from uniform 1 m compact ice. Variant ``packspun``: as ``spun`` (RD9), with the spin-up started from
``examples/winter_basin.toml``'s initial thickness and concentration expressions (``PACK_SETS``), family
``lead``, law ``same_pa``, the eight wind seeds, 20 and 10 km.
  (p) The thick-and-thin start adds to the fall if the pooled β on 20–120 km falls from 20 to 10 km by at least
      0.03 and is lower at 10 km in at least 6 of the 8 months.
  Predicted: (p) fails, with a fall of 0.012–0.025 as in RD9: the pack's structure varies over hundreds of
  kilometres, much wider than either element, so it should move where the bands form, not how the two meshes
  differ. If it fails, of the basin's pieces only its coast (and island) is left untested on the disk.

  Result (02:58 UTC): (p) holds, by 0.0005; the prediction was wrong. From the thick-and-thin spin-up the pooled β on
  20–120 km falls from 0.153 at 20 km to 0.123 at 10 km (a fall of 0.030), lower at 10 km in all 8 months
  (median −0.037; month by month −0.030, 90 % interval −0.039 to −0.019, against RD9's −0.017, −0.023 to
  −0.011, and the basin's −0.034, −0.060 to −0.006). The band length per area on day 28 is 1.81 times the
  20 km one (0.0457 against 0.0253 km⁻¹). Looked at after the verdict (no rule), paired by month against RD9:
  the pack raises β at 20 km by 0.016 (90 % interval 0.006 to 0.026) and leaves it at 10 km (+0.003, −0.005 to
  +0.011), so it adds −0.013 (−0.025 to 0.000) to the fall. With the basin's pack the disk's fall is the
  basin's; the coast is not needed for it.

Rule RD11 (written at 02:21 UTC, before its code and analysis; no new runs). RD5–RD9 read "the finer mesh cuts
the pack into smaller floes" from the band length per area, which counts every element above damage 0.9 as a
band as long as its size √area. That count doubles for a band of the same width in kilometres on a mesh of half
the size: it cannot tell more bands from bands more elements wide. Command ``floes`` measures, on days 4, 10,
16, 22 and 28 of RD5's months (pristine start) and RD9's (spun-up start), with the same band set (damage > 0.9,
elements whose centroid is at least 100 km from the coast):
  - the band perimeter length per area: half the length of the edges between a band element and an element
    outside the band, both in the interior, over the interior's area; a band of any width in elements counts
    once along its length;
  - the floes: the interior's elements outside the band set, joined through shared edges; their area-weighted
    mean area Σa²/Σa (the floe that a point of intact ice belongs to, on average).
  (q) The extra length is more bands, not wider ones, if on day 28 the perimeter length at 10 km is at least
      1.25 times the 20 km one (median over months), in both RD5's and RD9's months.
  (r) The finer mesh cuts the pack into smaller floes if on day 28 the area-weighted mean floe area at 10 km
      is at most 0.7 times the 20 km one (median over months), in both sets.
  Predicted: (q) and (r) hold (perimeter ratio 1.3–1.5, floe area ratio 0.4–0.7); the bands at 10 km are also
  wider in elements (perimeter ratio below the √area count's 1.65 and 1.9).

  Result (02:26 UTC): (q) and (r) hold in both sets; the prediction was right on both and wrong on the bands'
  width. On day 28 the band perimeter length at 10 km is 1.72 (RD5) and 1.75 (RD9) times the 20 km one, close
  to the √area count (1.65, 1.94): the bands are one element wide on both meshes on every day (18–22 km wide
  at 20 km, 9–11 km at 10 km). The area-weighted mean floe at 10 km is 0.69 and 0.51 times the 20 km one
  (15 000 → 10 400 km² and 21 800 → 11 100 km²). So the finer mesh does make more bands and smaller floes.
  But the floes' size does not carry the fall of β. Under the scaled law (RD6, reported, not judged) the 10 km
  floes are as large as the 20 km ones (×0.96; perimeter ×1.47), yet β falls by 0.020; without healing (RD8)
  they are smaller (×0.77), yet β falls by 0.010. Month by month (looked at after the verdict, no rule; 32
  months of the four sets) the change of β from 20 to 10 km correlates with the log of the floe-area ratio
  at r = +0.11 (within the sets +0.71, +0.55, −0.17, +0.08) and with the log of the perimeter ratio at
  +0.14. How far the pack is cut into floes is not what sets β's fall; RD7 had found the same by window.

Rule RD12 (written at 02:28 UTC, before its runs). RD8 suggested that healing makes about half of the disk's fall
(paired by month over eight months, −0.013, 90 % interval −0.027 to +0.001), not firmly. Eight more wind seeds
(2034–2041, ``MORE_MONTH_SEEDS``) for RD5's set (family ``lead``, law ``same_pa``, pristine) and RD8's
(``noheal``), at 20 and 10 km. Command ``healing``: per month and set, Δβ = β on 20–120 km at 10 km less at
20 km; healing's part is the mean over the months of Δβ(healing) − Δβ(no healing), paired by wind seed, with a
90 % interval from 10 000 resamplings of the months (seeded).
  (s) Healing's part is shown if, over the 16 months (2026–2041), its 90 % interval lies below 0.
  Predicted: (s) holds, with a part of −0.008 to −0.015. If it fails, healing's part is no larger than the
  months' noise, and the disk's fall does not need healing.
  The eight-month records of RD5 and RD8 stay as they were (``report --stage month`` reads the seeds 2026–2033
  unless given ``--seeds``).

  Result (03:50 UTC): (s) fails; the prediction was wrong. Over the 16 months healing's part is −0.010 (90 %
  interval −0.021 to +0.001); the eight new months alone give −0.007 (−0.024 to +0.010). Month by month the fall
  is −0.024 (−0.034 to −0.016) with healing and −0.015 (−0.023 to −0.006) without; pooled, 0.022 (0.153 → 0.131)
  and 0.016 (0.143 → 0.127). So the disk's fall does not need healing: without it the fall is there over 16
  months (RD8's eight had put its interval at −0.017 to 0.000), and healing's extra is within the months'
  noise.

Rule RD13 (written at 02:58 UTC, before its runs). RD10's pack differs from RD9's uniform 1 m compact ice in its
mean as well as its structure: over the disk its thickness averages 1.60 m and its concentration 0.920 (which
alone scales the stiffness and strength by exp(−20 × 0.08) = 0.20). Variant ``meanspun``: as ``packspun``, with
the spin-up started from uniform ice of the pack's means (1.6 m, 0.92), family ``lead``, law ``same_pa``, the
eight wind seeds (2026–2033), 20 and 10 km.
  (t) The pack's structure, not its mean, adds to the fall if the month-by-month fall (mean over the 8 months of
      β at 10 km less at 20 km on 20–120 km) is at least 0.008 smaller in size than RD10's (−0.030), i.e. above
      −0.022.
  Predicted: (t) fails (a fall of 0.025–0.035): the mean state, weaker and thicker, sets the fall as the
  strength did in the basin's families, and the structure adds little.

  Result (04:10 UTC): (t) fails, as predicted, but the fall is larger than predicted. From uniform ice of the pack's
  means the pooled β on 20–120 km falls from 0.171 at 20 km to 0.120 at 10 km (0.051), lower at 10 km in all 8
  months (month by month −0.048, 90 % interval −0.061 to −0.035; RD10's −0.030). Paired by month (after the
  verdict, no rule), the mean pack raises β at 20 km by 0.033 (0.025 to 0.041) over RD9's 1 m compact ice and
  leaves it at 10 km (+0.002, −0.009 to +0.012); the structure takes back 0.017 (0.004 to 0.028) at 20 km. At
  10 km β is 0.120–0.123 from all three spin-ups; at 20 km it is 0.139, 0.153 and 0.171. So the fall is the
  20 km mesh's β moving with the pack's mean state while the 10 km mesh's does not. (A correction to the rule's
  text: the concentration's factor exp(−20 (1 − A)) = 0.20 scales the elastic modulus, and its cube (α = 4) the
  relaxation time, to 0.008; it does not scale the cohesion. The mean pack is thicker, so 1.6 times the force
  at the same stress, five times softer and quicker to relax.)

Rule RD14 (written at 04:41 UTC, before its runs). RD13's uniform pack of the basin's means differs from RD9's 1 m
compact ice in two factors: its thickness (1.6 m, so the same wind stress makes 1/1.6 of the stress in the ice)
and its concentration (0.92, so the elastic modulus ×0.20 and the relaxation time ×0.008, the strength
unchanged). Variants ``thickspun`` (uniform 1.6 m, concentration 1) and ``concspun`` (uniform 1 m, concentration
0.92), otherwise as ``meanspun`` (the 14-day spin-up, family ``lead``, law ``same_pa``, the eight wind seeds
2026–2033, 20 and 10 km). Command ``factors``: for each of ``thickspun``, ``concspun`` and ``meanspun``, β on
20–120 km month by month less RD9's (``spun``) on the same mesh and wind seed, the mean over the 8 months with
its 90 % interval from 10 000 resamplings of the months (seeded).
  (u) The thickness raises the 20 km β if ``thickspun``'s paired change at 20 km is at least +0.015 and its 90 %
      interval lies above 0.
  (v) The concentration raises the 20 km β if ``concspun``'s does the same.
  Reported, not judged: the changes at 10 km, each variant's fall from 20 to 10 km, and whether the two changes
  at 20 km add up to ``meanspun``'s (+0.033).
  Predicted: (u) holds (+0.02 to +0.03) and (v) fails (0 to +0.01): thicker ice under the same wind is further
  below its strength, as a stronger pack would be; the concentration changes the modulus and the relaxation
  time, which set how fast stress moves and relaxes, not where the pack fails.

  Result (05:51 UTC): (u) and (v) fail; the prediction was wrong on the thickness. Paired with RD9's months, the
  thickness alone changes the 20 km β by −0.006 (90 % interval −0.017 to +0.006; pooled 0.133), the
  concentration alone by −0.017 (−0.024 to −0.010; pooled 0.120), where both together (RD13) raise it by +0.033:
  the two changes do not add up (−0.022 against +0.033). At 10 km every variant is within ±0.003 of RD9 (pooled
  0.120–0.121). Seen while the runs ran (``spinup_state``, no rule): every spin-up ends with an interior
  concentration of 0.986–0.992 (leads refreeze), so what it hands to the months is its thickness and its damage
  (elements above 0.9: 0.22–0.37 at 20 km, not in the order of the 20 km β).

Rule RD15 (written at 04:43 UTC, before its runs). RD13's fall (0.171 at 20 km, 0.120 at 10 km) is the 20 km β
moving, but two meshes cannot say which is nearer the converged answer. Variant ``meanspun`` on a 5 km mesh (its
own 14-day spin-up, the same cohesion in pascals, family ``lead``), months of wind seeds 2026 and 2027 only (the
first two of the eight, chosen before the runs; a 5 km month costs about 45 minutes of one core). Command
``fine``: β on 20–120 km of each 5 km month against the same month's at 10 and 20 km (RD13's record).
  (w) β keeps falling below 10 km if in both months it is lower at 5 km than at 10 km by at least 0.015.
  (x) β at 5 km turns back towards the 20 km value if in both months it is higher than at 10 km by at least 0.015.
  Neither: two months do not tell a change of 0.015 from the months' noise.
  Predicted: neither holds, the 5 km β within 0.015 of the 10 km one in at least one month: on one storm over
  pristine ice β on fixed widths did not change from 10 to 5 km (RD1), and the 10 km β stayed at 0.12 in every
  spin-up (RD13).

  Result (07:01 UTC): (w) holds; the prediction was wrong. β on 20–120 km is 0.097 and 0.088 at 5 km against
  0.153 and 0.136 at 10 km (0.171 and 0.180 at 20 km) in the months of wind seeds 2026 and 2027: lower by 0.056
  and 0.047. Pooled over the two months the 5 km β is 0.092. On the weeks of the climatology, β on fixed
  widths does not converge between 20 and 5 km: it falls by about 0.04–0.05 at each halving of the element.

Rule RD16 (written at 05:52 UTC, after RD14's result and before its runs). RD14 found that neither of the mean
pack's factors alone raises the 20 km β (1.6 m: −0.006; concentration 0.92: −0.017) where both together raise
it by +0.033, while the 10 km β is 0.120–0.123 from all five spin-ups. Every month of a set starts from the same
spun-up state, one realisation of the spin-up's weather, and the paired intervals count only the months' noise.
Variants ``spun2022``, ``spun2023`` and ``spun2024``: RD9's spin-up of uniform 1 m compact ice with the spin-up's
wind seed 2022, 2023 or 2024 instead of 2025, family ``lead``, law ``same_pa``, the eight wind seeds of the
months, at 20 km only (a 10 km month costs seven times a 20 km one). Command ``realisations``.
  (y) The spin-up's realisation moves the 20 km β as much as the pack's state did if the pooled 20 km β of the
      four realisations of the same pack (RD9's and the three new) spans at least 0.03 (largest less smallest).
  Predicted: (y) holds, with a span of 0.03–0.05: the five spin-ups' 20 km β (0.120–0.171) do not follow their
  factors, so one realisation of the spin-up's damage pattern decides much of it. If (y) holds, RD9–RD14's
  "the pack raises the 20 km β" is not shown, and the disk's fall from 20 to 10 km (−0.001 to 0.051 over the
  five spin-ups) is mostly the 20 km mesh's sensitivity to where the spin-up left its bands.

  Result (06:25 UTC): (y) holds, as predicted: the four realisations' pooled 20 km β are 0.139 (2025, RD9), 0.137
  (2022), 0.173 (2023) and 0.147 (2024), a span of 0.036; paired by month against 2025 the changes are 0.000,
  +0.037 and +0.009. The eight 20 km spin-ups (five packs, three realisations) give 0.120–0.173 (mean 0.147,
  standard deviation 0.018) and the five 10 km ones 0.120–0.123. So RD10's and RD13's "the pack raises the
  20 km β" is not shown (one realisation each, with intervals that count the months only), and the disk's fall
  from 20 to 10 km is about 0.026 on average, its size in one set mostly the 20 km mesh's realisation.

Rule RD17 (written at 08:12 UTC on 2026-12-01, before its runs). RD15 found β on 20–120 km lower at 5 km than at
10 km by 0.047–0.056 in two months, from one 5 km spin-up of one pack (``meanspun``). Variant ``spun`` (RD9's
spin-up of uniform 1 m compact ice, wind seed 2025) on a 5 km mesh, its own 14-day spin-up, months of wind
seeds 2026 and 2027 (the same two as RD15, chosen before the runs). Command ``fine --variant spun``: each 5 km
month against the same month's 10 and 20 km β (RD9's record).
  (w') β keeps falling below 10 km from another pack's spin-up if in both months it is lower at 5 km than at
       10 km by at least 0.015; (x') it turns back if higher by at least 0.015 in both; neither: not told.
  Predicted: (w') holds, by 0.03–0.05 in each month: RD15's fall was more than twice the 20 km realisations'
  spread, and the 10 km β did not depend on the pack (0.120–0.123 from all five spin-ups).

  Result (10:50 UTC): (w') holds, as predicted. β on 20–120 km is 0.098 and 0.090 at 5 km against 0.144 and 0.136
  at 10 km (0.158 and 0.151 at 20 km), lower by 0.046 and 0.047, as RD15's 0.056 and 0.047 from another pack.

Rule RD18 (written at 08:12 UTC on 2026-12-01, before its runs). RD16 found that the spin-up's realisation moves
the 20 km β by up to 0.034 (``spun2023``: 0.173 against ``spun``'s 0.139), while the five 10 km sets, each from
a different pack's spin-up, agree within 0.003; no realisation of one pack was run at 10 km. Variant
``spun2023`` (the realisation with the highest 20 km β) on the 10 km mesh, its own 14-day spin-up, the eight
wind seeds 2026–2033. Command ``realisations --km 10``: its pooled 10 km β against ``spun``'s (RD9's record),
and its months paired with ``spun``'s by wind seed.
  (z) The 10 km β does not follow the spin-up's realisation if the pooled 10 km β of ``spun2023`` lies within
      0.015 of ``spun``'s; it follows it if it is at least 0.02 higher.
  Predicted: (z) holds (within 0.01): the 10 km mesh's many bands average the spin-up's pattern out, where the
  20 km mesh's few bands keep it.

  Result (10:50 UTC): (z) holds, as predicted. ``spun2023``'s pooled 10 km β is 0.119 against ``spun``'s 0.120
  (paired by month −0.002, 90 % interval −0.014 to +0.010), where at 20 km it was 0.034 higher.

Rule RD19 (written at 14:43 UTC on 2026-12-01, before its runs; a 1-hour run at 40 km was made first to check that
the scene accepts the override, and none of its output was looked at but the log). Of the month's time-dependent
pieces, one storm on pristine ice has none and shows no fall; healing's part is within the months' noise (RD12);
a fixed mesh does not stop the basin's fall (forty-fifth session). Thermodynamics (ice growth, and new ice in the
leads that the bands open) was never taken out. Variant ``nothermo`` (``thermo.enabled = false``; healing keeps
its air temperature), family ``lead``, law ``same_pa``, pristine start, the 16 wind seeds 2026–2041, at 20 and
10 km. Command ``thermodynamics``: per month Δβ = β on 20–120 km at 10 km less at 20 km; thermodynamics' part is
Δβ(RD12's set with healing, from its record) − Δβ(no thermodynamics), paired by wind seed, mean and 90 % interval
from 10 000 resamplings of the months (seeded), as RD12.
  (t) The fall does not need thermodynamics if, without it, the mean month-by-month Δβ has its 90 % interval
      below 0.
  (t') Thermodynamics' part is shown if its 90 % interval excludes 0 (below 0: it makes the fall larger).
  Predicted: (t) holds, with a mean Δβ of −0.015 to −0.030; (t') is not shown (a part within ±0.01). Then the
  fall needs only the breaking and healing of the pack under weeks of storms.

  Result (03:25 UTC on 2026-12-02; the runs of 14:45 were lost with that session's machine and made again): (t)
  holds, with a smaller fall than predicted: without thermodynamics the mean Δβ is −0.012 (90 % interval −0.021
  to −0.003; pooled β on 20–120 km 0.152 at 20 km and 0.139 at 10 km). (t') is shown, against the prediction,
  only just: thermodynamics' part is −0.012 (−0.024 to −0.0003), about half the fall with it (−0.024), negative
  in 10 of 16 months. The two halves disagree: −0.003 over RD5's eight seeds (2026–2033; without thermodynamics
  β there is +0.003 at 20 km and +0.006 at 10 km against RD5, both intervals across 0) and −0.022 over the
  other eight, where the fall without thermodynamics is −0.019 and −0.006. A part shown by a margin of 0.0003,
  and carried by half the months, is read as weak evidence.

Rule RD20 (written at 14:44 UTC on 2026-12-01, before its runs and before RD19's result; a 1-hour run at 40 km was
made first to check that the scene accepts the overrides, and only its log was looked at). One storm on pristine
ice shows no fall; weeks of the climatology with all the month's pieces do (RD5, RD12). Which of the pieces the
fall needs is asked one at a time (healing: RD8, RD12; thermodynamics: RD19). Variant ``mechanics`` takes them all
out at once, leaving the damage mechanics under weeks of storms: no thermodynamics, no healing, no mesh motion and
no remeshing (the fields stay on the first mesh). Family ``lead``, law ``same_pa``, pristine start, wind seeds
2026–2033, at 20 and 10 km. Command ``mechanics``: per month Δβ = β on 20–120 km at 10 km less at 20 km, mean and
90 % interval from 10 000 resamplings of the months (seeded); beside it, the months paired on each mesh with
RD5's record.
  (u) The fall needs none of the month's pieces but its storms if the mean month-by-month Δβ has its 90 %
      interval below 0 and the pooled β on 20–120 km is at least 0.015 lower at 10 km.
  Predicted: (u) holds, with a fall of 0.01–0.03. Then the disk's fall is the damage law's answer to a sequence
  of storms on a fixed mesh, and can be studied without the Lagrangian machinery.

  Result (03:40 UTC on 2026-12-02; runs made again, as RD19's): (u) fails; the prediction was wrong. With the
  mechanics alone the pooled β on 20–120 km is 0.131 at 20 km and 0.129 at 10 km (a fall of 0.002); month by
  month Δβ is −0.004 (90 % interval −0.013 to +0.008), lower at 10 km in 6 of 8 months. Against RD5's months
  (all the pieces) the 20 km β is lower by 0.016 (−0.031 to −0.0003) and the 10 km β unchanged (+0.003,
  −0.003 to +0.008): taking the pieces out brings the 20 km β down to the 10 km one. Each piece taken out alone
  left a fall (healing: RD12, thermodynamics: RD19; the moving mesh and remeshing: the basin's fixed month of
  the forty-fifth session), so the fall needs at least one of them and no one of them alone is needed.

Rule RD21 (written at 03:43 UTC on 2026-12-02, after RD20's result and before its own runs; a 1-hour run at
40 km of each variant was made first to check that the scene accepts the overrides, and only its log was looked
at). RD20 took every time-dependent piece out of the month and the fall went with them, while each one taken out
alone left it. Which of them brings it back alone? Two variants put one piece back into ``mechanics``:
``mechheal`` (neXtSIM's healing back; no thermodynamics, fixed mesh) and ``mechmove`` (mesh motion and remeshing
back; no thermodynamics, no healing). Thermodynamics alone on the fixed mesh is not run: there the fields stay in
their elements, so no lead opens and no new ice forms, and it would only thicken the pack. Family ``lead``, law
``same_pa``, pristine start, wind seeds 2026–2033, 20 and 10 km. Command ``restoring``: per variant Δβ = β on
20–120 km at 10 km less at 20 km month by month, mean and 90 % interval (10 000 resamplings, seeded), the pooled
fall, and the piece's part, Δβ(variant) − Δβ(``mechanics``, from RD20's record), paired by wind seed.
  (x) Healing alone brings the fall back if ``mechheal``'s month-by-month Δβ has its 90 % interval below 0 and
      its pooled β on 20–120 km is at least 0.010 lower at 10 km.
  (y) The moving mesh alone brings it back if ``mechmove``'s does the same.
  Predicted: (x) holds, with a fall of 0.01–0.02 (healing's part in RD12 was −0.010, RD20's mechanics −0.004);
  (y) fails (a fixed mesh kept the basin's fall, forty-fifth session). Then the fall would come with a pack that
  heals and breaks again, which thermodynamics' new ice in the leads can stand in for.

  Result (15:05 UTC on 2026-12-02; runs made again in the next session, from this rule, the first runs being
  lost with that session's machine): (x) and (y) both fail; (x)'s prediction was wrong, (y)'s right. Healing
  alone: pooled β on 20–120 km 0.155 at 20 km and 0.148 at 10 km (a fall of 0.008); month by month Δβ −0.009
  (90 % interval −0.021 to +0.004), lower at 10 km in 5 of 8 months; healing's part −0.005 (−0.018 to
  +0.008). The moving mesh alone: 0.147 and 0.135 (a fall of 0.012, above the rule's 0.010); Δβ −0.011
  (−0.033 to +0.013), lower at 10 km in 5 of 8 months; its part −0.007 (−0.026 to +0.013). Each piece put back
  raises the 20 km β from the mechanics' 0.131 and leaves a fall half the size of all the pieces' (0.022, RD5
  and RD12), in the same direction, not shown over eight months: the months scatter by about 0.03 (the same
  three wind seeds, 2026, 2027 and 2030, have a higher β at 10 km in both sets). So no one piece was shown to
  bring the fall back; what the sets show together is a fall that grows with the number of pieces (0.002 with
  none, 0.008–0.012 with one, 0.013–0.016 with all but one, 0.022 with all), not a piece that carries it.

Rule RD22 (written at 15:07 UTC on 2026-12-02, after RD21's result and before its own runs). RD20 and RD21 rest
on eight months, whose Δβ scatter by about 0.03; the sets with every piece and with all but one have sixteen
(RD12, RD19). RD22 runs ``mechanics`` and ``mechheal`` on the other eight wind seeds (2034–2041; family
``lead``, law ``same_pa``, pristine start, 20 and 10 km), so that no pieces, one piece and every piece are
compared over the same sixteen months. Command ``counted``: per set Δβ = β on 20–120 km at 10 km less at 20 km,
month by month, mean and 90 % interval (10 000 resamplings, seeded), by the number of pieces (0: ``mechanics``;
1: ``mechheal``; 2: RD12's without healing and RD19's without thermodynamics; 3: RD12's with every piece, from
their records), and two parts paired by wind seed: the pieces' joint part, Δβ(every piece) − Δβ(``mechanics``),
and healing's part alone, Δβ(``mechheal``) − Δβ(``mechanics``). RD20's runs of ``mechanics`` on seeds 2026–2033
were lost with the fifty-seventh session's machine: their Δβ month by month comes from RD20's record.
  (p) The pieces together make the fall if the joint part's 90 % interval lies below 0.
  (q) Healing alone brings the fall back if ``mechheal``'s month-by-month Δβ has its 90 % interval below 0 and
      its pooled β on 20–120 km is at least 0.010 lower at 10 km (RD21's (x), over sixteen months).
  Predicted: (p) holds, with a joint part of −0.015 to −0.025; (q) fails, with a fall of 0.005–0.012 (RD21's
  mean, −0.009, and an interval that sixteen months narrow to about ±0.009 would reach 0).

  Result (15:43 UTC on 2026-12-02): (p) holds, (q) fails, as predicted; the joint part, −0.014 (90 %
  interval −0.026 to −0.002), is 0.001 short of the predicted range. Healing alone: Δβ −0.006 (−0.015 to +0.003),
  pooled fall 0.007 (within the predicted 0.005–0.012); healing's part against the mechanics +0.004 (−0.006 to
  +0.014). The new months change RD20's reading: over seeds 2034–2041 the mechanics alone has a fall of −0.017
  (against −0.004 over RD20's seeds 2026–2033), so over sixteen months its Δβ is −0.010 (−0.019 to −0.001),
  lower at 10 km in 11 of 16 months, and its pooled fall over the eight new months is 0.019. By the number of
  pieces, over the same sixteen months: none −0.010, healing alone −0.006, all but healing −0.015, all but
  thermodynamics −0.012, every piece −0.024 (lower at 10 km in 11, 11, 11, 11 and 15 months). So a fall of
  about 0.01 comes with the damage mechanics on a fixed mesh after all; RD20's "no fall" was its eight months';
  every piece together about doubles it, and no one piece was shown to.

Rule RD23 (written at 16:20 UTC on 2026-12-02, after RD22's result and before its own runs). RD21's (y), mesh
motion with remeshing put back alone into the mechanics, rests on eight months (Δβ −0.011, 90 % interval −0.033
to +0.013), as healing alone did before RD22 gave it sixteen. RD23 runs ``mechmove`` on the other eight wind
seeds (2034–2041; family ``lead``, law ``same_pa``, pristine start, 20 and 10 km), so that each piece that can be
put back alone has sixteen months (thermodynamics alone on a fixed mesh opens no lead: RD21). Command ``moved``:
``mechmove``'s Δβ = β on 20–120 km at 10 km less at 20 km month by month over sixteen months, mean and 90 %
interval (10 000 resamplings, seeded), its pooled fall over the runs on this machine, and the moving mesh's part
alone, Δβ(``mechmove``) − Δβ(``mechanics``), paired by wind seed (the mechanics' months 2026–2033 from RD20's
record, as in RD22).
  (y') The moving mesh alone keeps the fall if ``mechmove``'s month-by-month Δβ has its 90 % interval below 0 and
       its pooled β on 20–120 km is at least 0.010 lower at 10 km (RD21's (y), over sixteen months).
  (y'') The moving mesh's part is shown if its 90 % interval lies below 0 (it makes the fall larger than the
       mechanics' own).
  Predicted: (y') holds, with a mean Δβ of −0.010 to −0.016 (the mechanics' own −0.010 and RD21's −0.011 over
  eight months); (y'') fails, with a part within ±0.008, as healing's (+0.004). Then neither piece put back alone
  adds to the fall that the storms make on a fixed mesh, and only the pieces together do (RD22's joint part).
  Added at 16:29 UTC, while the runs were under way and before any of their results: with ``mechmove`` over
  sixteen months, the sets with the moving mesh and without healing differ only by thermodynamics.
  (y''') Thermodynamics' part where the mesh moves and nothing heals, Δβ(RD12's ``noheal``) − Δβ(``mechmove``),
       paired by wind seed, is shown if its 90 % interval lies below 0.
  Predicted: (y''') fails, with a part of −0.002 to −0.008 (RD19 showed thermodynamics' part with healing on,
  −0.012, by a margin of 0.0003).

  Result (16:53 UTC): (y') holds, with a larger fall than predicted; (y'') and (y''') fail, as predicted, with
  values at or beyond the edges of the predicted ranges. The moving mesh alone: Δβ −0.019 (90 % interval −0.031
  to −0.006), lower at 10 km in 13 of 16 months; pooled β on 20–120 km 0.162 at 20 km and 0.142 at 10 km (a fall
  of 0.021); −0.011 over RD21's eight seeds and −0.027 over the other eight. Its part against the mechanics is
  −0.009 (−0.021 to +0.003), 0.001 beyond the predicted ±0.008 and not shown. Thermodynamics' part where the mesh
  moves and nothing heals is +0.004 (−0.006 to +0.016), not shown, of the other sign than predicted. So over
  sixteen months the moving mesh with remeshing, put back alone, gives about four fifths of every piece's fall
  (−0.019 against −0.024) where healing alone gave a quarter (−0.006), but its part beyond the mechanics' own
  −0.010 is not shown, and the halves of its months differ by 0.016.

Rule RD24 (written at 16:40 UTC on 2026-12-02, before its runs and before RD23's result; a 1-hour run at 40 km
was made first to check that the scene accepts the overrides and that every element's cohesion is uniform on
[C, 2C], and only its log and its cohesion field were looked at). With the damage mechanics alone on a fixed
mesh β falls by about 0.010 from 20 to 10 km over sixteen months (RD22). On a fixed mesh the one thing that is
laid element by element is the white strength disorder: each element draws its own factor on [1, 2], so a 10 km
mesh holds four times as many independent draws per area, and all sixteen months share one draw per mesh (the
run seed is the same in every month). A disorder correlated over 40 km had left the basin's fall in one month
(forty-fourth session), which is weak evidence. Variant ``mechcorr``: ``mechanics``, with the white disorder off
and the correlated factor g on instead (``strength_correlation_m`` = 40 km, amplitude 1/3, C_lab × 1.5), so that
each element's cohesion is again uniform on [C, 2C] but laid by one field, the same on both meshes, that both
resolve. Family ``lead``, law ``same_pa``, pristine start, wind seeds 2026–2041, 20 and 10 km. Command
``correlated``: ``mechcorr``'s Δβ = β on 20–120 km at 10 km less at 20 km month by month, mean and 90 % interval
(10 000 resamplings, seeded), its pooled fall, and the disorder's part, Δβ(``mechcorr``) − Δβ(``mechanics``),
paired by wind seed (the mechanics' months from RD22's record).
  (v) The fall on a fixed mesh comes with the white disorder if that part's 90 % interval lies above 0 (with the
      correlated field the fall is smaller).
  (v') The fall does not need it if ``mechcorr``'s month-by-month Δβ has its 90 % interval below 0.
  Predicted: (v) fails and (v') holds, with a Δβ of −0.008 to −0.015, as the basin's month with the correlated
  field suggested. Then what makes β fall on a fixed mesh is the mesh itself (the bands one element wide), not
  how the strength is drawn on it.

  Result (17:27 UTC): (v) fails and (v') holds, as predicted, with a larger fall than predicted. With the
  correlated field the mechanics' Δβ is −0.019 (90 % interval −0.034 to −0.006), lower at 10 km in 10 of 16
  months; pooled β on 20–120 km 0.144 at 20 km and 0.127 at 10 km (a fall of 0.018). The disorder's part is
  −0.009 (−0.024 to +0.005): laid by one 40 km field that both meshes resolve, the disorder leaves the fall at
  least as large as the white one's (−0.010). So on a fixed mesh β falls from 20 to 10 km without an element
  scale in the strength and without a draw of its own on each mesh: what is left that differs between the two
  meshes is the mesh, whose bands are one element wide.

Rule RD25 (written at 17:29 UTC on 2026-12-02, after RD24's result and before its own runs; a 1-hour run at 40 km
was made first to check that the scene accepts the overrides, and only its log was looked at). If the fixed
mesh's fall comes from bands one element wide whose softening does not know their width, the two lengths the
damage law takes from the element should be given a physical length on both meshes: the damage time td = ℓ/cs
instead of Δx/cs (``rheology.damage_length_m``), and the crack band of the viscous flow, λ × Δx/ℓ, so that a band
of any width slips at the same rate under the same stress (``rheology.crack_band_length_m``; Bažant and Oh 1983).
Each was tried alone in the basin, with all its pieces, and left the fall there (forty-fourth and forty-fifth
sessions, one month each); together, and on the fixed mesh, they were not. Variant ``mechband``: ``mechanics``
with both, ℓ = 20 km. Family ``lead``, law ``same_pa``, pristine start, wind seeds 2026–2041, 20 and 10 km.
Command ``banded``: ``mechband``'s Δβ month by month, mean and 90 % interval (10 000 resamplings, seeded), its
pooled fall, and the regularisation's part, Δβ(``mechband``) − Δβ(``mechanics``), paired by wind seed (the
mechanics' months from RD22's record).
  (r) The regularisation makes the fall smaller if its part has its 90 % interval above 0.
  (r') The fall survives it if ``mechband``'s month-by-month Δβ has its 90 % interval below 0.
  Predicted: (r) fails and (r') holds, with a Δβ of −0.008 to −0.020: each length alone left the basin's fall.
  Then a band's width is not the cause in the form these two lengths can reach.

  Result (18:06 UTC): (r) fails and (r') holds, as predicted, but the fall is larger than predicted and the
  regularisation's part has the other sign: with both lengths at 20 km the mechanics' Δβ is −0.028 (90 % interval
  −0.042 to −0.015), lower at 10 km in 12 of 16 months; pooled β on 20–120 km 0.154 at 20 km and 0.126 at 10 km
  (a fall of 0.028). The part is −0.018 (−0.034 to −0.003): shown, and it makes the fall larger. The lengths
  change the 20 km mesh too (its elements' √area is about 13 km, so ℓ = 20 km slows its damage and speeds its
  bands' relaxation): over RD20's eight months, whose runs per month are in its record, they raise the 20 km β
  by 0.017 on average (0.148 against 0.131) and lower the 10 km β by 0.008 (0.120 against 0.128). So giving the
  damage law's two lengths a physical size does not make β the same on both meshes; the fall is not the element
  size entering td and λ.

    python benchmarks/disk_convergence.py run --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py run --family lead --law same_pa --more-seeds --jobs 2   # RD2
    python benchmarks/disk_convergence.py run --family shipped --law same_pa --more-seeds --jobs 2
    python benchmarks/disk_convergence.py run --family lead --law scaled --more-seeds --jobs 2       # RD4
    python benchmarks/disk_convergence.py report --family lead --law same_pa
    python benchmarks/disk_convergence.py basin lead20=B20-hthick-eff-C8-cap97-m20,... lead10=...   # RD3
    python benchmarks/disk_convergence.py run --stage month --family lead --law same_pa --jobs 2      # RD5
    python benchmarks/disk_convergence.py report --stage month --family lead --law same_pa
    python benchmarks/disk_convergence.py run --stage month --family lead --law scaled --jobs 2        # RD6
    python benchmarks/disk_convergence.py run --stage month --variant noheal --family lead --law same_pa --jobs 2  # RD8
    python benchmarks/disk_convergence.py fragmentation                                               # RD7
    python benchmarks/disk_convergence.py floes                                                       # RD11
    python benchmarks/disk_convergence.py run --stage month --family lead --law same_pa --seeds 2034 2035 2036 2037 \
        2038 2039 2040 2041 --jobs 2                                         # RD12, and the same with --variant noheal
    python benchmarks/disk_convergence.py healing                                                     # RD12
    python benchmarks/disk_convergence.py run --stage month --variant meanspun --family lead --law same_pa --jobs 2
    # (RD13)
    python benchmarks/disk_convergence.py run --stage month --variant thickspun --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py run --stage month --variant concspun --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py report --stage month --variant thickspun --family lead --law same_pa
    python benchmarks/disk_convergence.py factors                                                     # RD14
    python benchmarks/disk_convergence.py run --stage month --variant meanspun --km 5 --seeds 2026 2027 --jobs 2
    python benchmarks/disk_convergence.py fine                                                        # RD15
    python benchmarks/disk_convergence.py run --stage month --variant spun2022 --km 20 --family lead --law same_pa
    # (RD16; and spun2023, spun2024)
    python benchmarks/disk_convergence.py realisations                                                # RD16
    python benchmarks/disk_convergence.py run --stage month --variant spun --km 5 --seeds 2026 2027 --jobs 2
    python benchmarks/disk_convergence.py fine --variant spun                                         # RD17
    python benchmarks/disk_convergence.py run --stage month --variant spun2023 --km 10 --family lead --law same_pa
    python benchmarks/disk_convergence.py realisations --km 10                                        # RD18
    python benchmarks/disk_convergence.py run --stage month --variant nothermo --seeds 2026 2027 2028 2029 2030 \
        2031 2032 2033 2034 2035 2036 2037 2038 2039 2040 2041 --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py thermodynamics                                              # RD19
    python benchmarks/disk_convergence.py run --stage month --variant mechanics --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py mechanics                                                   # RD20
    python benchmarks/disk_convergence.py run --stage month --variant mechheal --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py run --stage month --variant mechmove --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py restoring                                                   # RD21
    python benchmarks/disk_convergence.py run --stage month --variant mechanics --seeds 2034 2035 2036 2037 2038 \
        2039 2040 2041 --family lead --law same_pa --jobs 2                  # RD22, and the same with mechheal
    python benchmarks/disk_convergence.py counted                                                     # RD22
    python benchmarks/disk_convergence.py run --stage month --variant mechmove --seeds 2034 2035 2036 2037 2038 \
        2039 2040 2041 --family lead --law same_pa --jobs 2                  # RD23
    python benchmarks/disk_convergence.py moved                                                       # RD23
    python benchmarks/disk_convergence.py run --stage month --variant mechcorr --seeds 2026 2027 2028 2029 2030 \
        2031 2032 2033 2034 2035 2036 2037 2038 2039 2040 2041 --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py correlated                                                  # RD24
    python benchmarks/disk_convergence.py run --stage month --variant mechband --seeds 2026 2027 2028 2029 2030 \
        2031 2032 2033 2034 2035 2036 2037 2038 2039 2040 2041 --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py banded                                                      # RD25

Rule RD26 (written at 18:49 UTC on 2026-12-02, after RD25's result and before its own runs; three 4-day runs
under wind seed 2099, which is none of the months, were made first to time the scheme and to check that the scene
accepts it, and only their logs were looked at: at 10 km about 100 simulated days per wall-hour with R = 40 km
and 205 with R = 20 km, against 515 with the local scheme; at 20 km with R = 40 km, 970). If the fixed mesh's fall
comes from bands one element wide, a band should get a width of its own inside the damage itself, which RD25's
two lengths do not give. The nonlocal damage (``rheology.damage_nonlocal_radius_m``, docs/physics.md §3; Bažant
and Jirásek 2002) drives an element's damage with the load ratio averaged over the centroids within R, so that a
band is at least about R wide on any mesh. It was extended this session to the effective failure stress of family
``lead`` (the ratio averaged is the effective stress's; tests/test_nonlocal_damage.py). In the basin, with the
nominal envelope and R up to 1.4 element sizes, β followed R/Δx (§3). Variant ``mechnl``: ``mechanics`` with
R = 40 km, two element sizes (``domain.resolution_m``) at 20 km and four at 10 km. A 10 km month costs about
17 minutes with it, five times the local scheme's, so eight months are run: wind seeds 2034–2041, chosen before
the runs as the eight whose mechanics show the fall (−0.017, against −0.004 over 2026–2033; RD22), so that there is
a fall to take away. Family ``lead``, law ``same_pa``, pristine start, 20 and 10 km. Command ``averaged``:
``mechnl``'s Δβ = β on 20–120 km at 10 km less at 20 km month by month, mean and 90 % interval (10 000
resamplings, seeded), its pooled fall, and the averaging's part, Δβ(``mechnl``) − Δβ(``mechanics``), paired by
wind seed (the mechanics' months from RD22's record); also β on each mesh against the mechanics', month by month.
  (a) The averaging makes the fall smaller if its part has its 90 % interval above 0.
  (a') The fall survives it if ``mechnl``'s month-by-month Δβ has its 90 % interval below 0.
  Predicted: (a) holds and (a') fails, with a Δβ of −0.005 to +0.030: with R fixed in kilometres the 10 km mesh
  holds the wider band in elements, and in the basin β rose with R/Δx. Then the width of a band, set inside the
  damage, decides how β moves with the element, and the local scheme's fall is its bands' width of one element.
  A caution written before the runs: the months were chosen for their fall, so a part above 0 could partly be
  the mechanics' months regressing; the same eight months gave the moving mesh a fall of −0.027 (RD23) and the
  other eight −0.011, so these months' larger falls are mostly their weather's.

  Result (21:25 UTC): (a) fails and (a') holds, against the prediction. With the load ratio averaged over 40 km
  the mechanics' Δβ is −0.019 (90 % interval −0.035 to −0.002), lower at 10 km in 5 of 8 months; pooled β on
  20–120 km 0.091 at 20 km and 0.074 at 10 km (a fall of 0.017). The averaging's part is −0.002 (−0.024 to
  +0.018): none. It lowers β on both meshes alike, by 0.054 at 20 km (−0.080 to −0.025) and 0.056 at 10 km
  (−0.068 to −0.044), against the mechanics' same months. So bands at least 40 km wide on both meshes keep the
  fall: it is not the bands' width of one element either.

    python benchmarks/disk_convergence.py run --stage month --variant mechnl --seeds 2034 2035 2036 2037 2038 \
        2039 2040 2041 --family lead --law same_pa --jobs 2
    python benchmarks/disk_convergence.py averaged                                                    # RD26
    python benchmarks/disk_convergence.py run --stage month --variant spun --family lead --law same_pa --jobs 2    # RD9
    python benchmarks/disk_convergence.py run --stage month --variant packspun --family lead --law same_pa --jobs 2
    # (RD10)

Runs go to ``benchmarks/out/disk_convergence/FAMILY-LAW-KMkm-sSEED`` (``lagice run`` subprocesses, one
numba thread each); ``report`` writes ``docs/figures/disk_convergence.json`` (every family and law run so
far) and ``docs/figures/disk_convergence_FAMILY_LAW.png``.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tomllib
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))  # validate.git_commit
OUT = ROOT / "benchmarks" / "out" / "disk_convergence"
JSON = ROOT / "docs" / "figures" / "disk_convergence.json"
SCENE = ROOT / "examples" / "imprint_cyclone_disk.toml"
#: stage ``month`` (rule RD5): the flagship's weather and time-dependent physics over the same disk
MONTH_SCENE = ROOT / "examples" / "winter_disk.toml"
DISK = "data_stubs/disk_500km.geojson"
DAY_S = 86400.0

KM = (20, 14, 10, 7, 5)
SEEDS = tuple(range(12, 18))
#: rule RD2's seeds (12 in all)
MORE_SEEDS = tuple(range(18, 24))
#: stage ``month``: the wind seeds of the basin's eight months (physics_experiments.py: the validation
#: month 2026, ENSEMBLE_SEEDS, MORE_SEEDS); the strength disorder is run.seed 2026's in every month
MONTH_SEEDS = tuple(range(2026, 2034))
MONTH_KM = (20, 10)
#: rule RD12's eight more wind seeds
MORE_MONTH_SEEDS = tuple(range(2034, 2042))
#: the variants whose months start from a spin-up, with the spin-up's own overrides. ``spun`` (rule RD9): each
#: month starts from the end of a 14-day run of the same scene, mesh and strength from pristine ice, under wind
#: seed 2025 from 1 January (as the basin's spin-up). ``packspun`` (rule RD10): the same, from the basin's
#: thick-and-thin pack (``examples/winter_basin.toml``'s initial thickness and concentration, the fields from
#: which ``examples/winter_basin_spinup.toml`` spins up the basin; the disk and the basin are both centred on 0)
PACK_SETS = [f'initial.{key}="{tomllib.loads((ROOT / "examples" / "winter_basin.toml").read_text())["initial"][key]}"'
             for key in ("thickness_m", "concentration")]
#: ``meanspun`` (rule RD13): the same spin-up from uniform ice of the pack's means over the disk
MEAN_PACK_SETS = ["initial.thickness_m=1.6", "initial.concentration=0.92"]
#: ``thickspun`` and ``concspun`` (rule RD14): the means one at a time, the other factor as RD9's compact 1 m ice
THICK_SETS = ["initial.thickness_m=1.6", "initial.concentration=1.0"]
CONC_SETS = ["initial.thickness_m=1.0", "initial.concentration=0.92"]
#: ``spun2022``–``spun2024`` (rule RD16): RD9's spin-up under another wind seed (replacing SPINUP_SETS's)
REALISATION_SEEDS = (2022, 2023, 2024)
SPUN_VARIANTS = {"spun": [], "packspun": PACK_SETS, "meanspun": MEAN_PACK_SETS, "thickspun": THICK_SETS,
                 "concspun": CONC_SETS, **{f"spun{sd}": [f"forcing.wind.seed={sd}"] for sd in REALISATION_SEEDS}}
#: stage ``month``'s variants (``--variant``): scene overrides of the months, the basin's pieces taken out or put
#: in one at a time (the spun-up ones' overrides are their state files, :func:`variant_sets`)
MONTH_VARIANTS = {"": [], "noheal": ["healing.law=none"], "nothermo": ["thermo.enabled=false"],
                  "mechanics": ["thermo.enabled=false", "healing.law=none", "lagrangian.enabled=false",
                                "remesh.enabled=false"],
                  "mechheal": ["thermo.enabled=false", "lagrangian.enabled=false", "remesh.enabled=false"],
                  "mechmove": ["thermo.enabled=false", "healing.law=none"],
                  "mechcorr": ["thermo.enabled=false", "healing.law=none", "lagrangian.enabled=false",
                               "remesh.enabled=false", "rheology.strength_disorder=0",
                               "rheology.strength_correlation_m=40e3",
                               "rheology.strength_correlated_amplitude=0.333333333333"],
                  "mechband": ["thermo.enabled=false", "healing.law=none", "lagrangian.enabled=false",
                               "remesh.enabled=false", "rheology.damage_length_m=20e3",
                               "rheology.crack_band_length_m=20e3"],
                  "mechnl": ["thermo.enabled=false", "healing.law=none", "lagrangian.enabled=false",
                             "remesh.enabled=false", "rheology.damage_nonlocal_radius_m=40e3"],
                  **{v: [] for v in SPUN_VARIANTS}}
#: rule RD24: C_lab factors of the month variants that change how the disorder is laid (``mechcorr``: the white
#: disorder's mean factor 1.5, so that with g on [2/3, 4/3] every element's cohesion is again uniform on [C, 2C])
VARIANT_LAB_FACTOR = {"mechcorr": 1.5}
SPINUP_SETS = ["forcing.wind.seed=2025", 'run.start_date="2026-01-01 00:00:00"', "run.duration=14d", "output.every=7d"]


def spinup_path(family: str, law: str, km: float, variant: str = "spun") -> Path:
    """The spin-up state of a variant in :data:`SPUN_VARIANTS` (``spun``'s keeps its first name)."""
    tag = "" if variant == "spun" else f"{variant}-"
    return OUT / f"spinup-{tag}{family}-{law}-{km:g}km.npz"


def spinup_command(family: str, law: str, km: float, variant: str = "spun") -> list:
    """The ``lagice run`` of :func:`make_spinup`."""
    cmd = [sys.executable, "-m", "lagice", "run", str(MONTH_SCENE), "--out",
           str(OUT / spinup_path(family, law, km, variant).stem)]
    mine = {x.split("=")[0] for x in SPUN_VARIANTS[variant]}
    base = [x for x in SPINUP_SETS if x.split("=")[0] not in mine]
    for x in [f"domain.resolution_m={km * 1e3:g}", f"rheology.strength_lab_pa={lab_cohesion_pa(family, law, km):.6g}",
              *FAMILIES[family][0], *base, *SPUN_VARIANTS[variant]]:
        cmd += ["--set", x]
    return cmd


def make_spinup(family: str, law: str, km: float, variant: str = "spun") -> str:
    """The variants of :data:`SPUN_VARIANTS`: the 14-day spin-up of ``examples/winter_disk.toml`` on the mesh of
    ``km`` (the family's settings, the law's strength and the variant's initial fields), its last snapshot saved
    by :func:`lagice.spinup.save_spinup`."""
    from lagice.spinup import save_spinup

    target = spinup_path(family, law, km, variant)
    if target.exists():
        return f"{target.name}: done before"
    out = OUT / target.stem
    cmd = spinup_command(family, law, km, variant)
    _lagice_run(cmd + (["--overwrite"] if out.exists() else []), target.stem)
    save_spinup(out, target)
    return f"{target.name}: made"


#: (scene overrides, C_lab [Pa] in lagice's form at the reference size)
FAMILIES = {
    "lead": (["rheology.failure_stress=effective", "rheology.max_damage=0.97"], 22.4e6),
    "shipped": ([], 2.80e6),
}
LAWS = ("same_pa", "scaled")
REFERENCE_KM = 20.0
#: the window: the cyclone's passage
WINDOW_DAYS = (1.0, 3.0)
COAST_BUFFER_M = 100e3
#: box widths every mesh resolves [m] (L of the estimator; inclusive)
COMMON_FIT_M = (25e3, 220e3)
MIN_BOXES = 10


def lab_cohesion_pa(family: str, law: str, km: float) -> float:
    """C_lab [Pa] for a mesh of ``km``: the family's value (``scaled``), or that value times
    √(Δx/20 km) so that the cohesion in pascals is the 20 km mesh's (``same_pa``)."""
    base = FAMILIES[family][1]
    return base * (np.sqrt(km / REFERENCE_KM) if law == "same_pa" else 1.0)


def variant_sets(variant: str, family: str, law: str, km: float) -> list:
    """The scene overrides of stage ``month``'s ``variant`` on the mesh of ``km`` (``spun``: the spin-up
    state of :func:`make_spinup` as the initial thickness, concentration and damage)."""
    if variant in SPUN_VARIANTS:
        return [f"initial.state_file={spinup_path(family, law, km, variant)}", "initial.thickness_m=from_state",
                "initial.concentration=from_state", "initial.damage=from_state"]
    return list(MONTH_VARIANTS[variant])


def _month_prefix(variant: str = "") -> str:
    return f"month-{variant}-" if variant else "month-"


def run_name(family: str, law: str, km: float, seed: int, stage: str = "storm", variant: str = "") -> str:
    """``FAMILY-LAW-KMkm-sSEED`` (one cyclone, disorder seed) or ``month[-VARIANT]-FAMILY-LAW-KMkm-wSEED``
    (wind seed)."""
    if stage == "month":
        return f"{_month_prefix(variant)}{family}-{law}-{km:g}km-w{seed}"
    return f"{family}-{law}-{km:g}km-s{seed}"


def command(family: str, law: str, km: float, seed: int, stage: str = "storm", variant: str = "") -> list:
    lab = lab_cohesion_pa(family, law, km) * (VARIANT_LAB_FACTOR.get(variant, 1.0) if stage == "month" else 1.0)
    sets = [f"domain.resolution_m={km * 1e3:g}", f"rheology.strength_lab_pa={lab:.6g}", *FAMILIES[family][0]]
    if stage == "month":
        scene, sets = MONTH_SCENE, [f"forcing.wind.seed={seed}", *sets, *variant_sets(variant, family, law, km)]
    else:
        scene, sets = SCENE, [f"domain.file={DISK}", f"run.seed={seed}", "output.every=6h", *sets]
    cmd = [sys.executable, "-m", "lagice", "run", str(scene), "--out",
           str(OUT / run_name(family, law, km, seed, stage, variant))]
    for s in sets:
        cmd += ["--set", s]
    return cmd


def _lagice_run(cmd: list, name: str) -> None:
    """``cmd`` (a ``lagice run``) with its output in ``OUT/NAME.log``, one numba thread unless the caller
    set ``NUMBA_NUM_THREADS``."""
    OUT.mkdir(parents=True, exist_ok=True)
    env = {**os.environ, "NUMBA_NUM_THREADS": os.environ.get("NUMBA_NUM_THREADS", "1")}
    with open(OUT / f"{name}.log", "w") as log:
        subprocess.run(cmd, check=True, stdout=log, stderr=subprocess.STDOUT, cwd=ROOT, env=env)


def run_one(family, law, km, seed, stage="storm", variant="") -> str:
    name = run_name(family, law, km, seed, stage, variant)
    if (OUT / name / "snapshots" / "index.json").exists():
        return f"{name}: done before"
    _lagice_run(command(family, law, km, seed, stage, variant), name)
    return f"{name}: made"


def common_beta(curve: dict) -> float:
    """β on the widths in :data:`COMMON_FIT_M` with at least :data:`MIN_BOXES` boxes (NaN if fewer
    than 2 such widths): the pool of one curve is the curve."""
    return float(_pool([curve], COMMON_FIT_M)[0].fit.exponent)


def _pool(curves, fit_range_m=None):
    """(:func:`lagice.diagnostics.scaling.pooled_spatial_scaling` of ``curves`` cut to the widths every one
    holds, with at least :data:`MIN_BOXES` boxes per fitted width; its slope per octave,
    −Δlog⟨ε̇tot⟩/Δlog L between successive widths)."""
    from lagice.diagnostics.scaling import pooled_spatial_scaling

    k = min(len(c["scale_m"]) for c in curves)
    cut = [{key: list(c[key][:k]) for key in ("box_size_m", "scale_m", "mean_total_s", "n_boxes")} for c in curves]
    pool = pooled_spatial_scaling(cut, min_boxes=MIN_BOXES, fit_range_m=fit_range_m)
    return pool, -np.diff(np.log(pool.mean_total_s)) / np.diff(np.log(pool.scale_m))


def _octaves(scale_m, slopes, fewest_boxes) -> str:
    """The slopes per octave as text, over the widths with at least :data:`MIN_BOXES` boxes."""
    return "  ".join(f"{scale_m[i] / 1e3:.0f}-{scale_m[i + 1] / 1e3:.0f}:{x:.3f}" for i, x in enumerate(slopes)
                     if fewest_boxes[i + 1] >= MIN_BOXES)


def _write_json(key: str, value: dict) -> None:
    """Set ``key`` of :data:`JSON` (other families, laws and the basin kept), with the commit whose code
    made it (``validate.git_commit``: HEAD, and whether files outside docs/ differ from it)."""
    from validate import git_commit

    value = {**value, "git_commit": git_commit()}
    data = json.loads(JSON.read_text()) if JSON.exists() else {}
    data[key] = value
    JSON.write_text(json.dumps(data, indent=1) + "\n")


def analyse_run(path: Path) -> dict:
    from lagice.diagnostics.windows import window_summary

    start, end = WINDOW_DAYS
    w = window_summary(path, start * DAY_S, (end - start) * DAY_S, COAST_BUFFER_M)
    s = w["interior"]
    return {"beta_common": common_beta(s["scaling_space"]), "beta_own": s["beta_space"],
            "mean_total_per_day": s["mean_total_s"] * DAY_S,
            "half_shear_area_fraction": s["localisation_half_shear_area_fraction"],
            "element_scale_m": s["element_scale_m"], "n_elements_interior": int(s["scaling_space"]["n_boxes"][0]),
            "curve": s["scaling_space"]}


def summarise(runs: dict) -> dict:
    """Per mesh: the medians over the seeds and a 90 % interval of the median (resampling seeds)."""
    rng = np.random.default_rng(0)
    out = {}
    for km in sorted({r["km"] for r in runs.values()}, reverse=True):
        rows = [r for r in runs.values() if r["km"] == km]
        row = {"n_seeds": len(rows)}
        for k in ("beta_common", "beta_own", "mean_total_per_day", "half_shear_area_fraction"):
            v = np.array([r[k] for r in rows], float)
            v = v[np.isfinite(v)]
            boot = np.median(rng.choice(v, size=(2000, v.size)), axis=1) if v.size else np.array([np.nan])
            row[k] = {"median": float(np.median(v)) if v.size else None,
                      "interval90": [float(np.quantile(boot, 0.05)), float(np.quantile(boot, 0.95))],
                      "values": [float(x) for x in v]}
        out[f"{km:g}"] = row
    return out


def pooled(runs: dict) -> dict:
    """Per mesh: the curve pooled over every box of every seed, its β on the common widths and on
    its own widths, and its slope per octave (rule RD2)."""
    out = {}
    for km in sorted({r["km"] for r in runs.values()}, reverse=True):
        curves = [r["curve"] for r in runs.values() if r["km"] == km]
        common, slopes = _pool(curves, COMMON_FIT_M)
        own, _ = _pool(curves)
        out[f"{km:g}"] = {"n_seeds": len(curves), "beta_common": float(common.fit.exponent),
                          "beta_own": float(own.fit.exponent), "scale_m": [float(x) for x in common.scale_m],
                          "mean_total_per_day": [float(x * DAY_S) for x in common.mean_total_s],
                          "fewest_boxes": [int(x) for x in common.fewest_boxes],
                          "slope_per_octave": [float(x) for x in slopes]}
    return out


def verdict_pooled(pool: dict) -> dict:
    """Rule RD2 (a) on the pooled β (common widths), (b) on the first and third octaves."""
    b = {float(k): v["beta_common"] for k, v in pool.items()}
    out = {}
    if all(k in b for k in (20.0, 10.0, 5.0)):
        spread = max(b[20.0], b[10.0], b[5.0]) - min(b[20.0], b[10.0], b[5.0])
        out.update({"pooled_spread_20_10_5": spread, "a_no_trend": bool(spread < 0.03),
                    "a_falls": bool(b[5.0] <= b[20.0] - 0.03)})
    flat = {k: (v["slope_per_octave"][0] < v["slope_per_octave"][2]) for k, v in pool.items()
            if len(v["slope_per_octave"]) >= 3 and v["fewest_boxes"][3] >= MIN_BOXES}
    out["b_first_octave_flatter"] = flat
    out["b_holds"] = bool(flat) and all(flat.values())
    return out


#: the basin's widths both a 20 km and a 10 km mesh resolve [m] (rule RD3)
BASIN_COMMON_FIT_M = (20e3, 120e3)
PHYSICS_OUT = ROOT / "benchmarks" / "out" / "physics"


def pool_windows(groups: dict) -> dict:
    """Per group of runs (``{name: [run folder, ...]}``): the curve pooled over every 3-day window (from
    day 1, 100 km from the coast), its β on its own widths, from the first box width (2Δx) on, and on
    :data:`BASIN_COMMON_FIT_M`, its slope per octave, and β on the common widths run by run (rules RD3,
    RD5)."""
    from lagice.diagnostics.windows import window_starts_days, window_summary

    out = {}
    for name, paths in groups.items():
        curves, per_run, by_start = [], {}, {}
        for path in paths:
            starts = window_starts_days(path, 3.0, start_day=1.0)
            mine = [window_summary(path, start * DAY_S, 3 * DAY_S, COAST_BUFFER_M)["interior"]["scaling_space"]
                    for start in starts]
            per_run[Path(path).name] = float(_pool(mine, BASIN_COMMON_FIT_M)[0].fit.exponent)
            curves += mine
            for start, c in zip(starts, mine):
                by_start.setdefault(float(start), []).append(c)
        own, slopes = _pool(curves)
        L = own.scale_m
        from2, _ = _pool(curves, (L[1] * 0.99, 1e9))
        common, _ = _pool(curves, BASIN_COMMON_FIT_M)
        out[name] = {"runs": [Path(x).name for x in paths], "n_windows": len(curves),
                     "beta_own": float(own.fit.exponent), "beta_from_2dx": float(from2.fit.exponent),
                     "beta_common": float(common.fit.exponent), "scale_m": [float(x) for x in L],
                     "mean_total_per_day": [float(x * DAY_S) for x in own.mean_total_s],
                     "fewest_boxes": [int(x) for x in own.fewest_boxes],
                     "slope_per_octave": [float(x) for x in slopes], "beta_common_per_run": per_run,
                     "beta_common_by_window_start_day": {f"{k:g}": float(_pool(v, BASIN_COMMON_FIT_M)[0].fit.exponent)
                                                         for k, v in sorted(by_start.items())}}
        r = out[name]
        print(f"{name}: {len(curves)} windows, β own {r['beta_own']:.3f}, from 2Δx {r['beta_from_2dx']:.3f}, "
              f"on {BASIN_COMMON_FIT_M[0] / 1e3:g}-{BASIN_COMMON_FIT_M[1] / 1e3:g} km {r['beta_common']:.3f}; "
              f"slope per octave {_octaves(L, slopes, r['fewest_boxes'])}")
        print("   β on the common widths, run by run:", " ".join(f"{v:.3f}" for v in per_run.values()))
    return out


def basin(groups: dict) -> dict:
    """:func:`pool_windows` of groups of basin runs (``{name: [run, ...]}`` in ``benchmarks/out/physics``)."""
    out = pool_windows({name: [PHYSICS_OUT / run for run in runs] for name, runs in groups.items()})
    data = json.loads(JSON.read_text()) if JSON.exists() else {}
    _write_json("basin", {**data.get("basin", {}), **out, "common_fit_m": list(BASIN_COMMON_FIT_M)})
    return out


def verdict_month(coarse: dict, fine: dict) -> dict:
    """Rule RD5 on two :func:`pool_windows` groups (20 km, 10 km): (e) the pooled β on the common widths
    falls by at least 0.02; (f) it is lower at 10 km in at least 6 of the months both meshes ran."""
    pairs = [(coarse["beta_common_per_run"][k], fine["beta_common_per_run"][k.replace("-20km-", "-10km-")])
             for k in coarse["beta_common_per_run"] if k.replace("-20km-", "-10km-") in fine["beta_common_per_run"]]
    fall = coarse["beta_common"] - fine["beta_common"]
    lower = sum(f < c for c, f in pairs)
    return {"fall_pooled_common": fall, "e_falls": bool(fall >= 0.02), "months_paired": len(pairs),
            "months_lower_at_10km": lower, "f_lower_in_6_of_8": bool(lower >= 6),
            "median_paired_change": float(np.median([f - c for c, f in pairs])) if pairs else None}


#: band length per area (rule RD6): the days at which it is read, and the damage of a band element
BAND_DAYS = (4, 10, 16, 22, 28)
BAND_DAMAGE = 0.9
DISK_RADIUS_M = 500e3


def _snapshots_by_day(path) -> dict:
    """{day of the run: snapshot file} of the run folder ``path`` (daily output)."""
    from lagice.io.snapshots import read_index

    return {round(e["time_s"] / DAY_S): Path(path) / "snapshots" / e["file"] for e in read_index(path)}


def band_snapshot(file) -> tuple:
    """One snapshot's mesh and band set: node x and y [m], the triangles, the element areas [m²], the interior
    (elements whose centroid is at least 100 km from the disk's coast) and the band set (interior elements
    with damage above :data:`BAND_DAMAGE`)."""
    import xarray as xr

    from lagice.mesh.core import signed_areas

    with xr.open_dataset(file, decode_times=False) as ds:
        x, y = ds["mesh_node_x"].values, ds["mesh_node_y"].values
        t = ds["mesh_face_nodes"].values.astype(np.int64)
        damage = ds["damage"].values[0]
    area = np.abs(signed_areas(np.column_stack([x, y]), t))
    inside = np.hypot(x[t].mean(axis=1), y[t].mean(axis=1)) < DISK_RADIUS_M - COAST_BUFFER_M
    return x, y, t, area, inside, inside & (damage > BAND_DAMAGE)


def band_length_per_km(path, days=BAND_DAYS) -> list:
    """Length of broken bands per interior area [km⁻¹] in the snapshots of ``days`` (rule RD6): the
    elements with damage above :data:`BAND_DAMAGE` at least 100 km from the disk's coast, each counted as
    a band as long as its size √area, over the interior's area. The same network of bands one element wide
    gives the same value on every mesh of the same element shape (a band of equilateral triangles is
    counted 1.3 times its length, one of right triangles from squares √2 times)."""
    by_day = _snapshots_by_day(path)
    out = []
    for day in days:
        _, _, _, area, inside, band = band_snapshot(by_day[day])
        out.append(float(np.sqrt(area[band]).sum() / area[inside].sum() * 1e3))
    return out


#: the smallest floe counted by :func:`band_perimeter_and_floes` [km²]: five equilateral elements of 20 km
MIN_FLOE_KM2 = 5 * np.sqrt(3.0) / 4 * 20.0 ** 2


def element_neighbours(triangles: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The elements that share an edge: ``(pairs, nodes)``, (k, 2) element indices and the shared edge's
    two nodes, one row per interior edge of the triangulation."""
    tri = np.asarray(triangles, np.int64)
    edges = np.sort(np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]]), axis=1)
    owner = np.tile(np.arange(len(tri)), 3)
    key = edges[:, 0] * (int(tri.max()) + 1) + edges[:, 1]
    order = np.argsort(key, kind="stable")
    first = np.flatnonzero(key[order][1:] == key[order][:-1])
    return np.column_stack([owner[order[first]], owner[order[first + 1]]]), edges[order[first]]


def floe_labels(pairs: np.ndarray, intact: np.ndarray) -> np.ndarray:
    """(m,) a floe label per element: the elements of ``intact`` joined through the shared edges ``pairs``
    (from :func:`element_neighbours`); the other elements are labelled too, each alone."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    join = intact[pairs[:, 0]] & intact[pairs[:, 1]]
    m = len(intact)
    graph = coo_matrix((np.ones(int(join.sum())), (pairs[join, 0], pairs[join, 1])), shape=(m, m))
    return connected_components(graph, directed=False)[1]


def band_perimeter_and_floes(path, days=BAND_DAYS) -> dict:
    """Rule RD11, per day of ``days``: the band set of :func:`band_length_per_km` (damage above
    :data:`BAND_DAMAGE`, 100 km from the coast) measured without counting elements:

    * ``perimeter_per_km``: half the length of the edges between a band element and an interior element
      outside the band, over the interior's area [km⁻¹] (a band of any width in elements counts once along
      its length);
    * ``band_width_km``: the band set's area over that length;
    * ``floe_area_km2``: the interior's elements outside the band set joined through shared edges into floes,
      their area-weighted mean area Σa²/Σa [km²];
    * ``n_floes_per_1e5_km2``: the floes of at least :data:`MIN_FLOE_KM2` per 10⁵ km² of interior."""
    by_day = _snapshots_by_day(path)
    out = {k: [] for k in ("perimeter_per_km", "band_width_km", "floe_area_km2", "n_floes_per_1e5_km2")}
    for day in days:
        x, y, t, area, inside, band = band_snapshot(by_day[day])
        pairs, nodes = element_neighbours(t)
        a, b = pairs[:, 0], pairs[:, 1]
        rim = inside[a] & inside[b] & (band[a] != band[b])
        seg = np.column_stack([x[nodes[rim, 1]] - x[nodes[rim, 0]], y[nodes[rim, 1]] - y[nodes[rim, 0]]])
        length_m = 0.5 * np.hypot(seg[:, 0], seg[:, 1]).sum()
        interior_m2 = area[inside].sum()
        out["perimeter_per_km"].append(float(length_m / interior_m2 * 1e3))
        out["band_width_km"].append(float(area[band].sum() / length_m / 1e3) if length_m > 0 else 0.0)
        intact = inside & ~band
        labels = floe_labels(pairs, intact)
        floes = np.bincount(labels[intact], weights=area[intact]) / 1e6
        floes = floes[floes > 0]
        out["floe_area_km2"].append(float((floes ** 2).sum() / floes.sum()))
        out["n_floes_per_1e5_km2"].append(float((floes >= MIN_FLOE_KM2).sum() / (interior_m2 / 1e6) * 1e5))
    return out



#: the month whose maps the figure shows (the validation month's weather) and the days shown
MAP_SEED, MAP_DAYS = 2026, (7, 16, 27)


def figure_month(family: str, law: str, groups: dict, pooled_windows: dict, path: Path) -> None:
    """Stage ``month``: the total deformation rate of the month of wind seed :data:`MAP_SEED` on
    :data:`MAP_DAYS` on each mesh, the band length per area against the day, and the pooled β on the common
    widths window by window."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import xarray as xr
    from matplotlib.colors import LogNorm

    kms = sorted(groups, key=float, reverse=True)
    fig, axes = plt.subplots(len(kms), len(MAP_DAYS) + 1, figsize=(4.2 * (len(MAP_DAYS) + 1), 4.0 * len(kms)),
                             layout="constrained")
    colours = {"20": "tab:blue", "10": "tab:red"}
    for row, km in enumerate(kms):
        run = next(p for p in groups[km] if Path(p).name.endswith(f"-w{MAP_SEED}"))
        by_day = _snapshots_by_day(run)
        for col, day in enumerate(MAP_DAYS):
            with xr.open_dataset(by_day[day], decode_times=False) as ds:
                x, y = ds["mesh_node_x"].values / 1e3, ds["mesh_node_y"].values / 1e3
                rate = ds["total_deformation_rate"].values[0] * DAY_S
                im = axes[row, col].tripcolor(x, y, ds["mesh_face_nodes"].values.astype(np.int64),
                                              facecolors=np.maximum(rate, 1e-4), norm=LogNorm(1e-3, 1.0),
                                              cmap="magma_r")
            axes[row, col].set_aspect("equal")
            axes[row, col].set_title(f"{km} km mesh, day {day}", fontsize=10)
            axes[row, col].set_xlabel("x (km)")
    fig.colorbar(im, ax=list(axes[:, :len(MAP_DAYS)].ravel()), label="total deformation rate (day⁻¹)", shrink=0.6)
    ax = axes[0, -1]
    for km in kms:
        b = pooled_windows[km]["band_length_per_km"]
        for runs in b["per_run"].values():
            ax.plot(b["days"], runs, color=colours.get(km, "k"), alpha=0.25, lw=0.8)
        ax.plot(b["days"], b["median"], "-o", color=colours.get(km, "k"), label=f"{km} km (median of months)")
    ax.set_xlabel("day")
    ax.set_ylabel("band length per area (km⁻¹)")
    ax.set_title(f"bands (damage > {BAND_DAMAGE:g}), ≥ 100 km from coast", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[1, -1] if len(kms) > 1 else ax
    for km in kms:
        w = pooled_windows[km]["beta_common_by_window_start_day"]
        ax.plot([float(k) + 1.5 for k in w], list(w.values()), "-s", color=colours.get(km, "k"), label=f"{km} km")
    ax.axhspan(0.17, 0.20, color="0.85", label="observed band (RGPS; for scale)")
    ax.set_xlabel("window centre (day)")
    ax.set_ylabel(f"β on {BASIN_COMMON_FIT_M[0] / 1e3:g}–{BASIN_COMMON_FIT_M[1] / 1e3:g} km, pooled over months")
    ax.set_title("β window by window", fontsize=10)
    ax.legend(fontsize=8)
    where = ("a 500 km disk, from a 14-day spin-up of the basin's thick-and-thin pack" if family.endswith("packspun")
             else "a 500 km disk, from a 14-day spin-up of uniform 1.6 m ice at concentration 0.92"
             if family.endswith("meanspun")
             else "a 500 km disk, from a 14-day spin-up" if family.endswith("spun") else "a pristine 500 km disk")
    fig.suptitle(f"28 days of the winter climatology over {where}: family {family}, strength {law}"
                 f" (maps: wind seed {MAP_SEED})", fontsize=11)
    fig.savefig(path, dpi=80)
    plt.close(fig)


def _seed_of(path) -> int:
    return int(Path(path).name.rsplit("-w", 1)[1])


def beta_by_seed(meshes: dict) -> dict:
    """``{"20": {wind seed: β}, "10": {...}}``: the β on the common widths run by run of a month set's meshes
    (a :func:`pool_windows` result or a record's ``meshes``), keyed by wind seed."""
    return {km: {_seed_of(k): v for k, v in meshes[km]["beta_common_per_run"].items()} for km in ("20", "10")}


def dbeta_by_seed(meshes: dict) -> dict:
    """``{wind seed: Δβ}`` in seed order: β on the common widths at 10 km less at 20 km, month by month, for
    the wind seeds run on both meshes of ``meshes`` (as :func:`beta_by_seed` takes it)."""
    per = beta_by_seed(meshes)
    return {sd: per["10"][sd] - per["20"][sd] for sd in sorted(per["20"]) if sd in per["10"]}


def finished_runs(paths: list, what: str) -> list:
    """``paths`` if every run in it has finished, else a SystemExit naming the ones that have not."""
    missing = [Path(p).name for p in paths if not (Path(p) / "snapshots" / "index.json").exists()]
    if missing:
        raise SystemExit(f"{what}: no finished run {missing} in {OUT}")
    return paths


def month_groups(family: str, law: str, variant: str = "", seeds=MONTH_SEEDS) -> dict:
    """``{"20": [run folder, ...], "10": [...]}``: the finished months of a set whose wind seed is in ``seeds``."""
    groups = {}
    for km in MONTH_KM:
        paths = [p for p in sorted(OUT.glob(f"{_month_prefix(variant)}{family}-{law}-{km:g}km-w*"))
                 if (p / "snapshots" / "index.json").exists() and _seed_of(p) in set(seeds)]
        if paths:
            groups[f"{km:g}"] = paths
    if len(groups) < 2:
        raise SystemExit(f"stage month: need finished runs of {_month_prefix(variant)}{family}-{law} at 20 and "
                         f"10 km in {OUT}")
    return groups


def report_month(family: str, law: str, variant: str = "", seeds=MONTH_SEEDS) -> dict:
    """Stage ``month`` (rules RD5, RD6, RD8): pool the 3-day windows of the months on each mesh, as ``basin``
    does for the basin's months, and judge the fall from 20 to 10 km. Months of other wind seeds than the
    eight of :data:`MONTH_SEEDS` are recorded under a key and figure of their own."""
    tag = "" if tuple(seeds) == MONTH_SEEDS else f"-w{min(seeds)}-{max(seeds)}"
    groups = month_groups(family, law, variant, seeds)
    out = pool_windows(groups)
    for km, paths in groups.items():
        bands = np.array([band_length_per_km(p) for p in paths])
        out[km]["band_length_per_km"] = {"days": list(BAND_DAYS), "median": [float(x) for x in np.median(bands, 0)],
                                         "per_run": {Path(p).name: [float(x) for x in b] for p, b in zip(paths, bands)}}
        print(f"{km} km: band length per area (km⁻¹, median over months) on days {BAND_DAYS}:",
              " ".join(f"{x:.4f}" for x in out[km]["band_length_per_km"]["median"]))
    v = verdict_month(out["20"], out["10"])
    ratio = out["10"]["band_length_per_km"]["median"][-1] / out["20"]["band_length_per_km"]["median"][-1]
    v.update({"band_length_ratio_10_to_20_last_day": ratio, "g_same_band_length": bool(0.8 <= ratio <= 1.25)})
    print("rules RD5 and RD6:", json.dumps(v))
    fig = ROOT / "docs" / "figures" / f"disk_month_{variant + '_' if variant else ''}{family}_{law}{tag}.png"
    figure_month(f"{family}{', ' + variant if variant else ''}", law, groups, out, fig)
    print(f"wrote {fig.relative_to(ROOT)}")
    _write_json(f"{_month_prefix(variant)}{family}-{law}{tag}",
                {"scene": str(MONTH_SCENE.relative_to(ROOT)),
                 "overrides": {km: [x.replace(f"{ROOT}/", "") for x in variant_sets(variant, family, law, float(km))]
                               for km in groups}, "meshes": out,
                 "common_fit_m": list(BASIN_COMMON_FIT_M), "verdict": v})
    return {"meshes": out, "verdict": v}


def verdict(summary: dict) -> dict:
    """Rule RD's two tests on the medians of β on the common widths, over the runs present (RD was stated
    for seeds 12–17; once RD2's seeds are made, ``report`` judges the twelve)."""
    med = {float(k): v["beta_common"]["median"] for k, v in summary.items()}
    if not all(k in med for k in (20.0, 10.0, 7.0, 5.0)):
        return {"complete": False}
    fall = med[20.0] - med[10.0]
    d7, d5 = med[7.0] - med[10.0], med[5.0] - med[10.0]
    return {"complete": True, "fall_20_to_10": fall, "R1_disk_reproduces_fall": bool(fall >= 0.02),
            "change_7_vs_10": d7, "change_5_vs_10": d5,
            "R2_converged_by_10km": bool(abs(d7) < 0.02 and abs(d5) < 0.02),
            "R2_keeps_falling": bool(d5 <= -0.02)}


def figure(family: str, law: str, summary: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import matplotlib.ticker

    keys = (("beta_common", "β, widths 25–220 km", (0.17, 0.20)),
            ("mean_total_per_day", "⟨ε̇tot⟩ (day⁻¹)", (0.01, 0.05)),
            ("half_shear_area_fraction", "area holding half the shear", (0.04, 0.08)))
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6))
    kms = sorted((float(k) for k in summary), reverse=True)
    for ax, (k, label, band) in zip(axes, keys):
        ax.axhspan(*band, color="0.85", label="observed band (RGPS, Arctic; for scale)")
        for km in kms:
            v = summary[f"{km:g}"][k]["values"]
            ax.plot([km] * len(v), v, "o", color="tab:blue", alpha=0.5, ms=4)
        med = [summary[f"{km:g}"][k]["median"] for km in kms]
        ax.plot(kms, med, "k-s", label="median over seeds")
        if k == "beta_common":
            own = [summary[f"{km:g}"]["beta_own"]["median"] for km in kms]
            ax.plot(kms, own, "--^", color="tab:red", label="β on each mesh's own widths (median)")
        ax.set_xscale("log")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xticks(kms)
        ax.set_xticklabels([f"{km:g}" for km in kms])
        ax.invert_xaxis()
        ax.set_xlabel("element size (km)")
        ax.set_title(label, fontsize=10)
        if k != "beta_common":
            ax.set_yscale("log")
    axes[0].legend(fontsize=7)
    fig.suptitle(f"one cyclone over a 500 km disk, days 1–3: family {family}, strength {law}", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def report(family: str, law: str) -> dict:
    runs = {}
    for path in sorted(OUT.glob(f"{family}-{law}-*km-s*")):
        if not (path / "snapshots" / "index.json").exists():
            continue
        km = float(path.name.split("-")[2][:-2])
        seed = int(path.name.split("-s")[-1])
        runs[path.name] = {"km": km, "seed": seed, **analyse_run(path)}
        r = runs[path.name]
        print(f"{path.name:28s} β common {r['beta_common']:.3f}  own {r['beta_own']:.3f}  "
              f"rate {r['mean_total_per_day']:.4f}/day  half-shear area {100 * r['half_shear_area_fraction']:.1f} %")
    if not runs:
        raise SystemExit(f"no finished runs of {family}-{law} in {OUT}")
    summary = summarise(runs)
    print(f"\n{'mesh':>6} {'seeds':>5} {'β common (90 %)':>24} {'β own':>7} {'rate/day':>9} {'half-shear':>10}")
    for km, row in summary.items():
        b = row["beta_common"]
        print(f"{km:>4}km {row['n_seeds']:>5} {b['median']:>8.3f} [{b['interval90'][0]:.3f}, {b['interval90'][1]:.3f}]"
              f" {row['beta_own']['median']:>7.3f} {row['mean_total_per_day']['median']:>9.4f}"
              f" {100 * row['half_shear_area_fraction']['median']:>9.1f}%")
    v = verdict(summary)
    print("\nrule RD:", json.dumps(v))
    pool = pooled(runs)
    print(f"\npooled over the seeds: {'mesh':>6} {'β common':>9} {'β own':>7}  slope per octave (L in km)")
    for km, row in pool.items():
        octs = _octaves(row["scale_m"], row["slope_per_octave"], row["fewest_boxes"])
        print(f"{'':22}{km:>4}km {row['beta_common']:>9.3f} {row['beta_own']:>7.3f}  {octs}")
    vp = verdict_pooled(pool)
    print("rule RD2:", json.dumps(vp))

    result = {"window_days": list(WINDOW_DAYS), "coast_buffer_m": COAST_BUFFER_M,
              "common_fit_m": list(COMMON_FIT_M), "summary": summary, "verdict": v, "pooled": pool,
              "verdict_pooled": vp,
              "runs": {k: {kk: vv for kk, vv in r.items() if kk != "curve"} for k, r in runs.items()}}
    _write_json(f"{family}-{law}", result)
    fig = ROOT / "docs" / "figures" / f"disk_convergence_{family}_{law}.png"
    figure(family, law, summary, fig)
    print(f"wrote {JSON.relative_to(ROOT)} and {fig.relative_to(ROOT)}")
    return result


#: rule RD7's bins of band length per area [km⁻¹] and the fewest windows a bin needs
FRAGMENTATION_BINS = (0.0, 0.02, 0.03, 0.04, np.inf)
FRAGMENTATION_MIN_WINDOWS = 8


def fragmentation(family: str = "lead", laws=("same_pa", "scaled")) -> dict:
    """Rule RD7: every 3-day window of the ``month`` runs of ``laws`` (the eight months of :data:`MONTH_SEEDS`)
    labelled by the band length per area on its first day; per mesh and bin of :data:`FRAGMENTATION_BINS`, the
    pooled β on :data:`BASIN_COMMON_FIT_M`. The 20 km runs of ``same_pa`` and ``scaled`` have the same cohesion
    (the same runs, bit for bit), so at 20 km only the first law's are taken."""
    from lagice.diagnostics.windows import window_starts_days, window_summary

    out = {}
    for km in MONTH_KM:
        bins = [[] for _ in FRAGMENTATION_BINS[:-1]]
        for law in (laws[:1] if float(km) == REFERENCE_KM else laws):
            for path in month_groups(family, law, "", MONTH_SEEDS).get(f"{km:g}", []):
                starts = window_starts_days(path, 3.0, start_day=1.0)
                lengths = band_length_per_km(path, days=[round(x) for x in starts])
                for start, length in zip(starts, lengths):
                    c = window_summary(path, start * DAY_S, 3 * DAY_S, COAST_BUFFER_M)["interior"]["scaling_space"]
                    bins[int(np.searchsorted(FRAGMENTATION_BINS, length, side="right")) - 1].append(c)
        row = []
        for i, curves in enumerate(bins):
            lo, hi = FRAGMENTATION_BINS[i], FRAGMENTATION_BINS[i + 1]
            beta = float(_pool(curves, BASIN_COMMON_FIT_M)[0].fit.exponent) if curves else None
            row.append({"band_length_per_km": [lo, None if np.isinf(hi) else hi], "n_windows": len(curves),
                        "beta_common": beta})
            print(f"{km} km, band length {lo:.2f}-{hi:.2f} km⁻¹: {len(curves):3d} windows, β on 20-120 km "
                  + (f"{beta:.3f}" if beta is not None else "-"))
        out[f"{km:g}"] = row
    v = verdict_fragmentation(out)
    print("rule RD7:", json.dumps(v))
    _write_json("fragmentation", {"family": family, "laws": list(laws), "bins": out, "verdict": v,
                                  "min_windows": FRAGMENTATION_MIN_WINDOWS})
    return {"bins": out, "verdict": v}


#: rule RD11's sets: (label, variant, law); the first two are judged, the others reported
FLOE_SETS = (("RD5", "", "same_pa"), ("RD9", "spun", "same_pa"), ("RD6", "", "scaled"), ("RD8", "noheal", "same_pa"))
FLOE_JUDGED = ("RD5", "RD9")


def floes(family: str = "lead") -> dict:
    """Rule RD11: the band perimeter length, the bands' width and the floes' size on both meshes of each set
    of :data:`FLOE_SETS` (the eight months of :data:`MONTH_SEEDS`), medians over the months per day, and the
    verdict on the judged sets."""
    result = {}
    for label, variant, law in FLOE_SETS:
        row = {}
        for km, paths in month_groups(family, law, variant, MONTH_SEEDS).items():
            per_run = {Path(p).name: band_perimeter_and_floes(p) for p in paths}
            row[km] = {"n_months": len(paths), "days": list(BAND_DAYS),
                              "median": {k: [float(v) for v in np.median([r[k] for r in per_run.values()], 0)]
                                         for k in next(iter(per_run.values()))},
                              "per_run": per_run}
        if len(row) < 2:
            continue
        med = {km: row[km]["median"] for km in row}
        ratio = {k: med["10"][k][-1] / med["20"][k][-1] for k in med["20"]}
        row["ratio_10_to_20_last_day"] = ratio
        result[label] = row
        print(f"{label} ({variant or 'pristine'}, {law}); days {BAND_DAYS}")
        for km in ("20", "10"):
            print(f"  {km} km: perimeter (km⁻¹) " + " ".join(f"{v:.4f}" for v in med[km]["perimeter_per_km"])
                  + " | width (km) " + " ".join(f"{v:.1f}" for v in med[km]["band_width_km"])
                  + " | floe area (km²) " + " ".join(f"{v:.0f}" for v in med[km]["floe_area_km2"])
                  + " | floes per 1e5 km² " + " ".join(f"{v:.1f}" for v in med[km]["n_floes_per_1e5_km2"]))
        print("  10/20 on day 28: " + ", ".join(f"{k} ×{v:.2f}" for k, v in ratio.items()))
    v = verdict_floes(result)
    print("rule RD11:", json.dumps(v))
    pairs = month_pairs(family, result)
    print("month by month (after the verdict; Δβ = β 10 km − β 20 km on 20–120 km):")
    for label, r in pairs["by_set"].items():
        print(f"  {label}: mean Δβ {r['mean_dbeta']:+.3f}; Pearson r of Δβ with log floe-area ratio "
              f"{r['r_floe']:+.2f}, with log perimeter ratio {r['r_perimeter']:+.2f}")
    print(f"  all {pairs['n']} months: r with log floe-area ratio {pairs['r_floe']:+.2f}, "
          f"with log perimeter ratio {pairs['r_perimeter']:+.2f}")
    result["month_pairs"] = pairs
    fig = ROOT / "docs" / "figures" / f"disk_month_floes_{family}.png"
    figure_floes(family, pairs, fig)
    print(f"wrote {fig.relative_to(ROOT)}")
    _write_json("floes", {"sets": result, "verdict": v, "band_damage": BAND_DAMAGE,
                          "min_floe_km2": MIN_FLOE_KM2})
    return {"sets": result, "verdict": v}


def figure_floes(family: str, pairs: dict, path: Path, seed: int = MAP_SEED, day: int = 28) -> None:
    """Rule RD11's figure: the floes (colours) and bands (black) of month ``seed`` on ``day`` on both meshes
    of the judged sets and RD6, and each month's Δβ against its floe-area ratio."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    sets = [s for s in FLOE_SETS if s[0] in ("RD5", "RD6", "RD9")]
    fig, axes = plt.subplots(2, len(sets) + 1, figsize=(4.2 * (len(sets) + 1), 8.4))
    rng = np.random.default_rng(0)
    palette = rng.uniform(0.35, 0.95, size=(4096, 3))
    for col, (label, variant, law) in enumerate(sets):
        for row, km in enumerate(MONTH_KM):
            ax = axes[row, col]
            run = OUT / run_name(family, law, km, seed, "month", variant)
            x, y, t, _, inside, band = band_snapshot(_snapshots_by_day(run)[day])
            x, y = x / 1e3, y / 1e3
            labels = floe_labels(element_neighbours(t)[0], inside & ~band)
            colour = palette[labels % len(palette)]
            colour[band] = 0.0
            colour[~inside] = 0.9
            tc = ax.tripcolor(x, y, t, facecolors=np.zeros(len(t)), edgecolors="none")
            tc.set_array(None)
            tc.set_facecolor(colour)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"{label} ({variant or 'pristine'}, {law}), {km} km", fontsize=9)
    ax = axes[0, -1]
    markers = {"RD5": "o", "RD9": "s", "RD6": "^", "RD8": "v"}
    for label, r in pairs["by_set"].items():
        ax.scatter([m["floe_area_km2_ratio"] for m in r["months"]], [m["dbeta"] for m in r["months"]],
                   marker=markers.get(label, "x"), label=f"{label} (r = {r['r_floe']:+.2f})")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(1.0, color="0.6", lw=0.8)
    ax.set_xlabel(f"floe area, 10 km / 20 km (day {day})")
    ax.set_ylabel("Δβ on 20–120 km, 10 km − 20 km")
    ax.set_title(f"each month (all: r = {pairs.get('r_floe', np.nan):+.2f})", fontsize=9)
    ax.legend(fontsize=7)
    ax = axes[1, -1]
    for label, r in pairs["by_set"].items():
        ax.scatter([m["perimeter_per_km_ratio"] for m in r["months"]], [m["dbeta"] for m in r["months"]],
                   marker=markers.get(label, "x"), label=f"{label} (r = {r['r_perimeter']:+.2f})")
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.set_xlabel(f"band perimeter length, 10 km / 20 km (day {day})")
    ax.set_ylabel("Δβ on 20–120 km, 10 km − 20 km")
    ax.legend(fontsize=7)
    fig.suptitle(f"Floes (colours) and bands of damage > {BAND_DAMAGE} (black) on day {day} of wind seed {seed}, "
                 f"100 km from the disk's coast; right: every month of each set", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=80)
    plt.close(fig)


def month_pairs(family: str, result: dict) -> dict:
    """Each month of each set of ``result`` paired by wind seed: the change of its β on the common widths
    from 20 to 10 km (from the set's record in ``disk_convergence.json``, written by ``report --stage month``)
    against the day-28 ratios (10 over 20 km) of its floe area and of its band perimeter length; Pearson's r
    of Δβ with the logarithm of each ratio, per set and over all months."""
    record = json.loads(JSON.read_text()) if JSON.exists() else {}
    rows, by_set = [], {}
    for label, variant, law in FLOE_SETS:
        key = f"{_month_prefix(variant)}{family}-{law}"
        if label not in result or key not in record:
            continue
        beta = {km: record[key]["meshes"][km]["beta_common_per_run"] for km in ("20", "10")}
        runs = {km: result[label][km]["per_run"] for km in ("20", "10")}
        mine = []
        for name20, b20 in beta["20"].items():
            name10 = name20.replace("-20km-", "-10km-")
            if name10 in beta["10"] and name20 in runs["20"] and name10 in runs["10"]:
                mine.append({"month": name20.rsplit("-w", 1)[1], "dbeta": beta["10"][name10] - b20,
                             **{f"{k}_ratio": runs["10"][name10][k][-1] / runs["20"][name20][k][-1]
                                for k in ("floe_area_km2", "perimeter_per_km")}})
        if len(mine) < 3:
            continue
        rows += mine
        by_set[label] = {"months": mine, "mean_dbeta": float(np.mean([m["dbeta"] for m in mine])),
                         **_pair_correlations(mine)}
    return {"by_set": by_set, "n": len(rows), **(_pair_correlations(rows) if len(rows) >= 3 else {})}


def _pair_correlations(rows: list) -> dict:
    db = np.array([r["dbeta"] for r in rows])
    return {f"r_{name}": float(np.corrcoef(db, np.log([r[f"{key}_ratio"] for r in rows]))[0, 1])
            for name, key in (("floe", "floe_area_km2"), ("perimeter", "perimeter_per_km"))}


def verdict_floes(result: dict) -> dict:
    """Rule RD11 (q) and (r) on the sets of :data:`FLOE_JUDGED` (ratios of the day-28 medians, 10 over 20 km)."""
    judged = {k: result[k]["ratio_10_to_20_last_day"] for k in FLOE_JUDGED if k in result}
    return {"perimeter_ratio": {k: r["perimeter_per_km"] for k, r in judged.items()},
            "floe_area_ratio": {k: r["floe_area_km2"] for k, r in judged.items()},
            "q_more_bands": len(judged) == len(FLOE_JUDGED) and all(r["perimeter_per_km"] >= 1.25
                                                                    for r in judged.values()),
            "r_smaller_floes": len(judged) == len(FLOE_JUDGED) and all(r["floe_area_km2"] <= 0.7
                                                                       for r in judged.values())}


def mean_interval(values, n_resamplings: int = 10_000, seed: int = 0) -> tuple[float, float, float]:
    """The mean of ``values`` and its 90 % interval from ``n_resamplings`` resamplings with replacement."""
    x = np.asarray(values, dtype=float)
    means = x[np.random.default_rng(seed).integers(0, x.size, (n_resamplings, x.size))].mean(axis=1)
    lo, hi = np.percentile(means, [5.0, 95.0])
    return float(x.mean()), float(lo), float(hi)


def healing(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD12: Δβ (β on 20–120 km at 10 km less at 20 km) month by month with healing and without, and
    healing's part, Δβ(healing) − Δβ(no healing) paired by wind seed, with its 90 % interval."""
    dbeta, sets = {}, {}
    for label, variant in (("healing", ""), ("no healing", "noheal")):
        pooled = pool_windows(month_groups(family, law, variant, seeds))
        dbeta[label] = dbeta_by_seed(pooled)
        sets[label] = {"fall_pooled_common": pooled["20"]["beta_common"] - pooled["10"]["beta_common"],
                       "n_months": len(dbeta[label]),
                       "dbeta_by_month": {str(k): v for k, v in sorted(dbeta[label].items())},
                       "mean_dbeta_interval": mean_interval(list(dbeta[label].values()))}
    common = sorted(set(dbeta["healing"]) & set(dbeta["no healing"]))
    part = [dbeta["healing"][sd] - dbeta["no healing"][sd] for sd in common]
    v = verdict_healing(part)
    halves = {name: mean_interval([p for sd, p in zip(common, part) if sd in chosen])
              for name, chosen in (("seeds 2026-2033", MONTH_SEEDS), ("seeds 2034-2041", MORE_MONTH_SEEDS))
              if any(sd in chosen for sd in common)}
    for label, r in sets.items():
        m, lo, hi = r["mean_dbeta_interval"]
        print(f"{label}: {r['n_months']} months, pooled fall {r['fall_pooled_common']:.3f}; month by month "
              f"Δβ {m:+.3f} [{lo:+.3f}, {hi:+.3f}]")
    print("healing's part by half:", {k: [round(x, 3) for x in val] for k, val in halves.items()})
    print("rule RD12:", json.dumps(v))
    _write_json("healing", {"family": family, "law": law, "sets": sets, "months_paired": common,
                            "healing_part_by_month": dict(zip(map(str, common), part)),
                            "healing_part_by_half": halves, "verdict": v})
    return {"sets": sets, "verdict": v}


def verdict_healing(part) -> dict:
    """Rule RD12 (s): healing's part is shown if the 90 % interval of its mean lies below 0."""
    m, lo, hi = mean_interval(part)
    return {"n_months": len(part), "healing_part": m, "interval_90": [lo, hi], "s_shown": bool(hi < 0.0)}


def verdict_thermodynamics(dbeta_without: list, part: list) -> dict:
    """Rule RD19 (t), (t'): the fall without thermodynamics is there if the 90 % interval of its mean Δβ lies
    below 0; thermodynamics' part is shown if the 90 % interval of its mean excludes 0."""
    m, lo, hi = mean_interval(dbeta_without)
    pm, plo, phi = mean_interval(part)
    return {"n_months": len(part), "dbeta_without_thermo": m, "dbeta_without_interval_90": [lo, hi],
            "t_fall_without_thermo": bool(hi < 0.0), "thermo_part": pm, "thermo_part_interval_90": [plo, phi],
            "t_prime_part_shown": bool(plo > 0.0 or phi < 0.0)}


def thermodynamics(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD19: Δβ (β on 20–120 km at 10 km less at 20 km) month by month without thermodynamics (variant
    ``nothermo``), and thermodynamics' part, Δβ(RD12's set with healing, from its record) − Δβ(nothermo), paired
    by wind seed; beside it, the first eight months paired with RD5's record on each mesh."""
    data = json.loads(JSON.read_text())
    pooled = pool_windows(month_groups(family, law, "nothermo", seeds))
    mine = dbeta_by_seed(pooled)
    base = {int(k): v for k, v in data["healing"]["sets"]["healing"]["dbeta_by_month"].items()}
    common = sorted(set(mine) & set(base))
    part = [base[sd] - mine[sd] for sd in common]
    v = verdict_thermodynamics([mine[sd] for sd in common], part)
    fall = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
    rd5 = data[f"month-{family}-{law}"]
    record = {"meshes": {km: {"beta_common_per_run": {k: b for k, b in pooled[km]["beta_common_per_run"].items()
                                                      if _seed_of(k) in MONTH_SEEDS},
                              "beta_common": pooled[km]["beta_common"]} for km in ("20", "10")}}
    against_rd5 = paired_changes(record, rd5)
    print(f"no thermodynamics: {len(mine)} months, pooled β on 20-120 km {pooled['20']['beta_common']:.3f} at 20 km, "
          f"{pooled['10']['beta_common']:.3f} at 10 km (fall {fall:.3f})")
    print("against RD5's eight months, paired:", json.dumps(against_rd5))
    print("rule RD19:", json.dumps(v))
    _write_json("thermodynamics", {"family": family, "law": law, "months_paired": common,
                                   "dbeta_by_month_without": {str(k): mine[k] for k in sorted(mine)},
                                   "thermo_part_by_month": dict(zip(map(str, common), part)),
                                   "beta_common": {km: pooled[km]["beta_common"] for km in ("20", "10")},
                                   "beta_common_per_run": {km: pooled[km]["beta_common_per_run"]
                                                           for km in ("20", "10")},
                                   "fall_pooled_common": fall, "against_rd5_first_eight": against_rd5,
                                   "verdict": v})
    return v


def verdict_mechanics(dbeta: list, fall_pooled: float) -> dict:
    """Rule RD20 (u): the fall is there with the mechanics alone if the 90 % interval of the mean month-by-month
    Δβ lies below 0 and the pooled β on 20–120 km is at least 0.015 lower at 10 km."""
    m, lo, hi = mean_interval(dbeta)
    return {"n_months": len(dbeta), "dbeta": m, "dbeta_interval_90": [lo, hi], "fall_pooled_common": fall_pooled,
            "u_fall_with_mechanics_alone": bool(hi < 0.0 and fall_pooled >= 0.015)}


def mechanics(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS) -> dict:
    """Rule RD20: variant ``mechanics``'s months (no thermodynamics, healing, mesh motion or remeshing), Δβ month
    by month and pooled, and the months paired on each mesh with RD5's record."""
    data = json.loads(JSON.read_text())
    pooled = pool_windows(month_groups(family, law, "mechanics", seeds))
    mine = dbeta_by_seed(pooled)
    fall = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
    v = verdict_mechanics(list(mine.values()), fall)
    record = {"meshes": {km: {k: pooled[km][k] for k in ("beta_common_per_run", "beta_common")} for km in ("20", "10")}}
    against_rd5 = paired_changes(record, data[f"month-{family}-{law}"])
    print(f"mechanics alone: {len(mine)} months, pooled β on 20-120 km {pooled['20']['beta_common']:.3f} at 20 km, "
          f"{pooled['10']['beta_common']:.3f} at 10 km (fall {fall:.3f})")
    print("against RD5, paired:", json.dumps(against_rd5))
    print("rule RD20:", json.dumps(v))
    _write_json("mechanics", {"family": family, "law": law, "overrides": MONTH_VARIANTS["mechanics"],
                              "dbeta_by_month": {str(k): x for k, x in mine.items()},
                              "beta_common": {km: pooled[km]["beta_common"] for km in ("20", "10")},
                              "beta_common_per_run": {km: pooled[km]["beta_common_per_run"] for km in ("20", "10")},
                              "mean_total_per_day": {km: pooled[km]["mean_total_per_day"] for km in ("20", "10")},
                              "against_rd5": against_rd5, "verdict": v})
    return v


#: rule RD21: the variants that put one piece back into ``mechanics``, and the rule's letter for each
RESTORING_VARIANTS = {"mechheal": "x_healing_alone", "mechmove": "y_moving_mesh_alone"}


def verdict_restoring(dbeta: list, fall_pooled: float, part: list) -> dict:
    """Rule RD21 (x) or (y): one piece put back brings the fall back if the 90 % interval of the mean
    month-by-month Δβ lies below 0 and the pooled β on 20–120 km is at least 0.010 lower at 10 km; the piece's
    part (Δβ less ``mechanics``'s, paired) is reported with its interval."""
    m, lo, hi = mean_interval(dbeta)
    pm, plo, phi = mean_interval(part)
    return {"n_months": len(dbeta), "dbeta": m, "dbeta_interval_90": [lo, hi], "fall_pooled_common": fall_pooled,
            "part": pm, "part_interval_90": [plo, phi], "brings_fall_back": bool(hi < 0.0 and fall_pooled >= 0.010)}


def restoring(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS) -> dict:
    """Rule RD21: for ``mechheal`` and ``mechmove``, Δβ month by month and pooled, and the piece's part against
    RD20's ``mechanics`` record, paired by wind seed."""
    data = json.loads(JSON.read_text())
    base = {int(k): v for k, v in data["mechanics"]["dbeta_by_month"].items()}
    out, verdict = {}, {}
    for variant, letter in RESTORING_VARIANTS.items():
        pooled = pool_windows(month_groups(family, law, variant, seeds))
        mine = dbeta_by_seed(pooled)
        common = sorted(set(mine) & set(base))
        fall = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
        v = verdict_restoring([mine[sd] for sd in common], fall, [mine[sd] - base[sd] for sd in common])
        verdict[letter] = v["brings_fall_back"]
        print(f"{variant}: {len(mine)} months, pooled β on 20-120 km {pooled['20']['beta_common']:.3f} at 20 km, "
              f"{pooled['10']['beta_common']:.3f} at 10 km (fall {fall:.3f})")
        print(f"rule RD21 ({variant}):", json.dumps(v))
        out[variant] = {"overrides": MONTH_VARIANTS[variant], "dbeta_by_month": {str(k): x for k, x in mine.items()},
                        "beta_common": {km: pooled[km]["beta_common"] for km in ("20", "10")},
                        "beta_common_per_run": {km: pooled[km]["beta_common_per_run"] for km in ("20", "10")},
                        "mean_total_per_day": {km: pooled[km]["mean_total_per_day"] for km in ("20", "10")},
                        "verdict": v}
    _write_json("restoring", {"family": family, "law": law, "variants": out, "verdict": verdict})
    return verdict


def verdict_counted(joint_part: list, heal_dbeta: list, heal_fall_pooled: float) -> dict:
    """Rule RD22 (p): the pieces together make the fall if the 90 % interval of their joint part (Δβ with every
    piece less Δβ with the mechanics alone, paired) lies below 0; (q): healing alone brings the fall back if
    ``mechheal``'s month-by-month Δβ has its 90 % interval below 0 and its pooled fall is at least 0.010."""
    pm, plo, phi = mean_interval(joint_part)
    hm, hlo, hhi = mean_interval(heal_dbeta)
    return {"n_months": len(joint_part), "joint_part": pm, "joint_part_interval_90": [plo, phi],
            "healing_alone_dbeta": hm, "healing_alone_dbeta_interval_90": [hlo, hhi],
            "healing_alone_fall_pooled_common": heal_fall_pooled,
            "p_pieces_make_the_fall": bool(phi < 0.0),
            "q_healing_alone": bool(hhi < 0.0 and heal_fall_pooled >= 0.010)}


def counted(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD22: Δβ month by month over sixteen months by the number of time-dependent pieces (0 ``mechanics``,
    1 ``mechheal``, 2 RD12's without healing and RD19's without thermodynamics, 3 RD12's with every piece, the
    last three from their records), the pieces' joint part and healing's part alone, paired by wind seed."""
    data = json.loads(JSON.read_text())
    mine, falls, from_record = {}, {}, {}
    records = {"mechanics": data["mechanics"]["dbeta_by_month"],
               "mechheal": data["restoring"]["variants"]["mechheal"]["dbeta_by_month"]}
    for variant in ("mechanics", "mechheal"):
        pooled = pool_windows(month_groups(family, law, variant, seeds))
        mine[variant] = dbeta_by_seed(pooled)
        falls[variant] = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
        # months whose runs are not on this machine come from RD20's and RD21's records (Δβ month by month)
        from_record[variant] = sorted(int(sd) for sd in records[variant] if int(sd) not in mine[variant])
        mine[variant].update({sd: records[variant][str(sd)] for sd in from_record[variant]})
    recs = {"every piece": data["healing"]["sets"]["healing"]["dbeta_by_month"],
            "without healing": data["healing"]["sets"]["no healing"]["dbeta_by_month"],
            "without thermodynamics": data["thermodynamics"]["dbeta_by_month_without"]}
    sets = {"mechanics": mine["mechanics"], "mechheal": mine["mechheal"]}
    sets.update({k: {int(sd): x for sd, x in v.items()} for k, v in recs.items()})
    pieces = {"mechanics": 0, "mechheal": 1, "without healing": 2, "without thermodynamics": 2, "every piece": 3}
    common = sorted(set.intersection(*(set(v) for v in sets.values())))
    joint = [sets["every piece"][sd] - sets["mechanics"][sd] for sd in common]
    heal_part = mean_interval([sets["mechheal"][sd] - sets["mechanics"][sd] for sd in common])
    v = verdict_counted(joint, [sets["mechheal"][sd] for sd in common], falls["mechheal"])
    v["healing_alone_part"], v["healing_alone_part_interval_90"] = heal_part[0], list(heal_part[1:])
    by_set = {}
    for name, d in sets.items():
        m, lo, hi = mean_interval([d[sd] for sd in common])
        by_set[name] = {"pieces": pieces[name], "dbeta": m, "dbeta_interval_90": [lo, hi],
                        "months_lower_at_10km": int(sum(d[sd] < 0.0 for sd in common))}
        print(f"{name} ({pieces[name]} pieces): {len(common)} months, Δβ {m:+.3f} [{lo:+.3f}, {hi:+.3f}], lower at "
              f"10 km in {by_set[name]['months_lower_at_10km']}")
    print("pooled falls on 20-120 km, over the runs on this machine:", {k: round(x, 4) for k, x in falls.items()},
          "; months from the records:", from_record)
    print("rule RD22:", json.dumps(v))
    _write_json("counted", {"family": family, "law": law, "months": common, "by_set": by_set,
                            "fall_pooled_common": falls, "months_from_records": from_record, "verdict": v,
                            "dbeta_by_month": {k: {str(sd): d[sd] for sd in common} for k, d in sets.items()}})
    return v



def verdict_moved(dbeta: list, fall_pooled: float, part: list) -> dict:
    """Rule RD23 (y'): the moving mesh alone keeps the fall if ``mechmove``'s month-by-month Δβ has its 90 %
    interval below 0 and its pooled fall is at least 0.010 (RD21's (y)); (y''): its part against the mechanics
    (paired) is shown if that part's 90 % interval lies below 0."""
    v = verdict_restoring(dbeta, fall_pooled, part)
    return {"n_months": v["n_months"], "dbeta": v["dbeta"], "dbeta_interval_90": v["dbeta_interval_90"],
            "fall_pooled_common": fall_pooled, "part": v["part"], "part_interval_90": v["part_interval_90"],
            "y1_moving_mesh_alone_keeps_fall": v["brings_fall_back"],
            "y2_moving_mesh_part_shown": bool(v["part_interval_90"][1] < 0.0)}


def moved(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD23: ``mechmove``'s Δβ month by month over sixteen months and its pooled fall, and the moving mesh's
    part alone, Δβ(``mechmove``) − Δβ(``mechanics``), paired by wind seed (the mechanics' months not run on this
    machine, and ``mechmove``'s, from the ``counted`` and ``restoring`` records)."""
    data = json.loads(JSON.read_text())
    pooled = pool_windows(month_groups(family, law, "mechmove", seeds))
    mine = dbeta_by_seed(pooled)
    fall = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
    record = data["restoring"]["variants"]["mechmove"]["dbeta_by_month"]
    from_record = sorted(int(sd) for sd in record if int(sd) not in mine and int(sd) in seeds)
    mine.update({sd: record[str(sd)] for sd in from_record})
    base = {int(k): x for k, x in data["counted"]["dbeta_by_month"]["mechanics"].items()}
    common = sorted(set(mine) & set(base))
    v = verdict_moved([mine[sd] for sd in common], fall, [mine[sd] - base[sd] for sd in common])
    halves = {name: mean_interval([mine[sd] for sd in common if sd in part])[0]
              for name, part in (("2026-2033", MONTH_SEEDS), ("2034-2041", MORE_MONTH_SEEDS))}
    v["months_lower_at_10km"] = int(sum(mine[sd] < 0.0 for sd in common))
    noheal = {int(k): x for k, x in data["healing"]["sets"]["no healing"]["dbeta_by_month"].items()}
    both = [sd for sd in common if sd in noheal]
    tm, tlo, thi = mean_interval([noheal[sd] - mine[sd] for sd in both])
    v.update({"thermo_part_moving_mesh": tm, "thermo_part_moving_mesh_interval_90": [tlo, thi],
              "y3_thermo_part_shown": bool(thi < 0.0), "thermo_part_months": len(both)})
    print(f"mechmove: {len(common)} months, pooled β on 20-120 km {pooled['20']['beta_common']:.3f} at 20 km, "
          f"{pooled['10']['beta_common']:.3f} at 10 km over the runs on this machine (fall {fall:.3f}); "
          f"months from the record: {from_record}; Δβ by halves {json.dumps(halves)}")
    print("rule RD23:", json.dumps(v))
    _write_json("moved", {"family": family, "law": law, "overrides": MONTH_VARIANTS["mechmove"], "months": common,
                          "dbeta_by_month": {str(sd): mine[sd] for sd in common}, "dbeta_by_half": halves,
                          "beta_common": {km: pooled[km]["beta_common"] for km in ("20", "10")},
                          "beta_common_per_run": {km: pooled[km]["beta_common_per_run"] for km in ("20", "10")},
                          "months_from_record": from_record, "verdict": v})
    return v


def _fall_and_part(dbeta: list, part: list) -> dict:
    """Mean month-by-month Δβ and a part (paired differences), each with its 90 % interval."""
    m, lo, hi = mean_interval(dbeta)
    pm, plo, phi = mean_interval(part)
    return {"n_months": len(dbeta), "dbeta": m, "dbeta_interval_90": [lo, hi], "part": pm,
            "part_interval_90": [plo, phi]}


def verdict_correlated(dbeta: list, part: list) -> dict:
    """Rule RD24 (v): the fall on a fixed mesh comes with the white disorder if the disorder's part (Δβ with the
    correlated field less Δβ with the white disorder, paired) has its 90 % interval above 0; (v'): it does not
    need it if the correlated set's month-by-month Δβ has its 90 % interval below 0."""
    v = _fall_and_part(dbeta, part)
    return {**v, "v_fall_with_white_disorder": bool(v["part_interval_90"][0] > 0.0),
            "v2_fall_without_white_disorder": bool(v["dbeta_interval_90"][1] < 0.0)}


def verdict_banded(dbeta: list, part: list) -> dict:
    """Rule RD25 (r): the band-width regularisation makes the fixed mesh's fall smaller if its part (Δβ with it
    less Δβ without, paired) has its 90 % interval above 0; (r'): the fall survives it if the regularised set's
    month-by-month Δβ has its 90 % interval below 0."""
    v = _fall_and_part(dbeta, part)
    return {**v, "r_regularisation_reduces_fall": bool(v["part_interval_90"][0] > 0.0),
            "r2_fall_survives": bool(v["dbeta_interval_90"][1] < 0.0)}


def against_mechanics(variant: str, rule: str, verdict, family: str = "lead", law: str = "same_pa",
                      seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> tuple[dict, dict]:
    """Rules RD24 and RD25: a fixed-mesh variant of the mechanics, its Δβ month by month and pooled fall, and its
    part, Δβ(``variant``) − Δβ(``mechanics``), paired by wind seed (the mechanics' months from RD22's record);
    ``verdict(dbeta, part)`` judges them. Returns (verdict, record)."""
    data = json.loads(JSON.read_text())
    pooled = pool_windows(month_groups(family, law, variant, seeds))
    mine = dbeta_by_seed(pooled)
    fall = pooled["20"]["beta_common"] - pooled["10"]["beta_common"]
    base = {int(k): x for k, x in data["counted"]["dbeta_by_month"]["mechanics"].items()}
    common = sorted(set(mine) & set(base))
    v = verdict([mine[sd] for sd in common], [mine[sd] - base[sd] for sd in common])
    v["fall_pooled_common"] = fall
    v["months_lower_at_10km"] = int(sum(mine[sd] < 0.0 for sd in common))
    print(f"{variant}: {len(common)} months, pooled β on 20-120 km {pooled['20']['beta_common']:.3f} at 20 km, "
          f"{pooled['10']['beta_common']:.3f} at 10 km (fall {fall:.3f})")
    print(f"rule {rule}:", json.dumps(v))
    record = {"family": family, "law": law, "overrides": MONTH_VARIANTS[variant], "months": common,
              "dbeta_by_month": {str(sd): mine[sd] for sd in common},
              "beta_common": {km: pooled[km]["beta_common"] for km in ("20", "10")},
              "beta_common_per_run": {km: pooled[km]["beta_common_per_run"] for km in ("20", "10")},
              "mean_total_per_day": {km: pooled[km]["mean_total_per_day"] for km in ("20", "10")}}
    return v, record


def correlated(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD24: ``mechcorr`` (the disorder correlated over 40 km) against the mechanics."""
    v, record = against_mechanics("mechcorr", "RD24", verdict_correlated, family, law, seeds)
    _write_json("correlated", {**record, "lab_factor": VARIANT_LAB_FACTOR["mechcorr"], "verdict": v})
    return v


def banded(family: str = "lead", law: str = "same_pa", seeds=MONTH_SEEDS + MORE_MONTH_SEEDS) -> dict:
    """Rule RD25: ``mechband`` (a damage time and a crack band of 20 km) against the mechanics."""
    v, record = against_mechanics("mechband", "RD25", verdict_banded, family, law, seeds)
    _write_json("banded", {**record, "verdict": v})
    return v

def verdict_averaged(dbeta: list, part: list) -> dict:
    """Rule RD26 (a): the nonlocal damage makes the fixed mesh's fall smaller if its part (Δβ with it less Δβ
    without, paired) has its 90 % interval above 0; (a'): the fall survives it if the averaged set's
    month-by-month Δβ has its 90 % interval below 0."""
    v = _fall_and_part(dbeta, part)
    return {**v, "a_averaging_reduces_fall": bool(v["part_interval_90"][0] > 0.0),
            "a2_fall_survives": bool(v["dbeta_interval_90"][1] < 0.0)}


def averaged(family: str = "lead", law: str = "same_pa", seeds=MORE_MONTH_SEEDS) -> dict:
    """Rule RD26: ``mechnl`` (the damage driven by the load ratio averaged over 40 km) against the mechanics, and
    β on each mesh against the mechanics' runs of the same months (paired by wind seed)."""
    v, record = against_mechanics("mechnl", "RD26", verdict_averaged, family, law, seeds)
    months = record["months"]
    mine = beta_by_seed({km: {"beta_common_per_run": record["beta_common_per_run"][km]} for km in ("20", "10")})
    theirs = beta_by_seed(pool_windows(month_groups(family, law, "mechanics", tuple(months))))
    for km in ("20", "10"):
        both = sorted(set(mine[km]) & set(theirs[km]))
        m, lo, hi = mean_interval([mine[km][sd] - theirs[km][sd] for sd in both])
        v[f"change_{km}km_against_mechanics"] = [m, lo, hi]
        print(f"{km} km: β against the mechanics' {m:+.3f} [{lo:+.3f}, {hi:+.3f}] over {len(both)} months")
    _write_json("averaged", {**record, "verdict": v})
    return v

#: rule RD14: the spun-up variants whose β is paired with RD9's (``spun``)
FACTOR_VARIANTS = ("thickspun", "concspun", "meanspun")


def paired_changes(record: dict, base: dict) -> dict:
    """β on the common widths of a month set's ``record`` (a ``report --stage month`` entry of
    ``disk_convergence.json``) less ``base``'s, paired by wind seed on each mesh, and the record's own change
    from 20 to 10 km, each as (mean over the months, 90 % interval)."""
    p, b = beta_by_seed(record["meshes"]), beta_by_seed(base["meshes"])
    out = {}
    for km in ("20", "10"):
        seeds = sorted(set(p[km]) & set(b[km]))
        out[f"change_{km}km"] = mean_interval([p[km][sd] - b[km][sd] for sd in seeds])
        out[f"months_{km}km"] = len(seeds)
    seeds = sorted(set(p["20"]) & set(p["10"]))
    out["fall_10_less_20"] = mean_interval([p["10"][sd] - p["20"][sd] for sd in seeds])
    out["beta_pooled"] = {km: record["meshes"][km]["beta_common"] for km in ("20", "10")}
    return out


def verdict_factors(changes: dict) -> dict:
    """Rule RD14 (u), (v): a factor raises the 20 km β if its paired change is ≥ +0.015 with the 90 % interval
    above 0; reported: whether the two factors' changes at 20 km add up to ``meanspun``'s (within 0.01)."""
    def raises(v):
        m, lo, _ = changes[v]["change_20km"]
        return bool(m >= 0.015 and lo > 0.0)

    total = changes["thickspun"]["change_20km"][0] + changes["concspun"]["change_20km"][0]
    return {"u_thickness_raises_20km": raises("thickspun"), "v_concentration_raises_20km": raises("concspun"),
            "sum_of_factors_20km": total, "meanspun_20km": changes["meanspun"]["change_20km"][0],
            "factors_add_up": bool(abs(total - changes["meanspun"]["change_20km"][0]) <= 0.01)}


def spinup_state(family: str = "lead", law: str = "same_pa", variants=tuple(SPUN_VARIANTS)) -> dict:
    """The state each spin-up of ``variants`` hands to its months, per mesh: over the elements whose centroid is
    at least :data:`COAST_BUFFER_M` from the coast (element means; the meshes are near uniform), the mean
    damage, the fraction of elements above :data:`BAND_DAMAGE`, the mean thickness [m] and concentration."""
    out = {}
    for v in variants:
        for km in MONTH_KM:
            path = spinup_path(family, law, km, v)
            if not path.exists():
                continue
            z = np.load(path)
            inner = np.hypot(z["centroid_x_m"], z["centroid_y_m"]) <= DISK_RADIUS_M - COAST_BUFFER_M
            d = z["damage"][inner]
            out.setdefault(v, {})[f"{km:g}"] = {
                "mean_damage": float(d.mean()), "band_fraction": float((d > BAND_DAMAGE).mean()),
                "mean_thickness_m": float(z["thickness"][inner].mean()),
                "mean_concentration": float(z["concentration"][inner].mean())}
    return out


def figure_factors(family: str, law: str, data: dict, path: Path) -> None:
    """Rule RD14: β on 20–120 km of every month (dots) and pooled (bars) at 20 and 10 km, for each spun-up start,
    with the observed band."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    starts = [("spun", "1 m, A 1\n(RD9)"), ("thickspun", "1.6 m, A 1\n(RD14)"), ("concspun", "1 m, A 0.92\n(RD14)"),
              ("meanspun", "1.6 m, A 0.92\n(RD13)"), ("packspun", "thick-and-thin\n(RD10)")]
    starts = [(v, label) for v, label in starts if f"month-{v}-{family}-{law}" in data]
    n_real = len(data.get("realisations", {}).get("beta_common_per_run", {}))
    fig, ax = plt.subplots(figsize=(9.5 + 1.6 * n_real, 4.6), layout="constrained")
    ax.axhspan(0.17, 0.20, color="0.85", label="observed β (0.17–0.20)")
    for i, (v, _) in enumerate(starts):
        meshes = data[f"month-{v}-{family}-{law}"]["meshes"]
        for km, dx, colour in (("20", -0.17, "tab:blue"), ("10", 0.17, "tab:red")):
            betas = list(meshes[km]["beta_common_per_run"].values())
            ax.bar(i + dx, meshes[km]["beta_common"], width=0.3, color=colour, alpha=0.35,
                   label=f"{km} km, pooled" if i == 0 else None)
            ax.plot(np.full(len(betas), i + dx), betas, "o", ms=4, color=colour,
                    label=f"{km} km, each month" if i == 0 else None)
    labels = [label for _, label in starts]
    real = data.get("realisations", {})
    for v, betas in real.get("beta_common_per_run", {}).items():
        # rule RD16: RD9's spin-up under another wind seed, the 20 km mesh only
        i = len(labels)
        ax.bar(i - 0.17, real["beta_common_20km"][v], width=0.3, color="tab:blue", alpha=0.35)
        ax.plot(np.full(len(betas), i - 0.17), list(betas.values()), "o", ms=4, color="tab:blue")
        labels.append(f"1 m, A 1, spin-up\nwind {v[4:]} (RD16)")
    ax.set_xticks(range(len(labels)), labels, fontsize=8 if len(labels) > 5 else None)
    ax.set_ylabel("β on 20–120 km")
    ax.set_ylim(0.0, 0.28)
    ax.set_title(f"The disk's months from {len(starts) + n_real} 14-day spin-ups ({family}, {law.replace('_', ' ')}; "
                 "eight wind seeds)")
    ax.legend(loc="upper center", fontsize=8, ncol=5)
    fig.savefig(path, dpi=90)
    plt.close(fig)


def factors(family: str = "lead", law: str = "same_pa") -> dict:
    """Rule RD14: each of :data:`FACTOR_VARIANTS` against RD9's spun-up compact 1 m ice, from the month sets'
    records (``report --stage month --variant V`` first)."""
    data = json.loads(JSON.read_text())
    key = f"{family}-{law}"
    missing = [v for v in ("spun", *FACTOR_VARIANTS) if f"month-{v}-{key}" not in data]
    if missing:
        raise SystemExit(f"factors: no record of {missing} in {JSON.relative_to(ROOT)}; run report --stage month "
                         "--variant V first")
    changes = {v: paired_changes(data[f"month-{v}-{key}"], data[f"month-spun-{key}"]) for v in FACTOR_VARIANTS}
    for v, c in changes.items():
        print(f"{v}: pooled β {c['beta_pooled']['20']:.3f} (20 km) {c['beta_pooled']['10']:.3f} (10 km); against "
              "spun: " + ", ".join(f"{km} km {c[f'change_{km}km'][0]:+.3f} [{c[f'change_{km}km'][1]:+.3f}, "
                                   f"{c[f'change_{km}km'][2]:+.3f}]" for km in ("20", "10"))
              + f"; fall {c['fall_10_less_20'][0]:+.3f} [{c['fall_10_less_20'][1]:+.3f}, "
                f"{c['fall_10_less_20'][2]:+.3f}]")
    v = verdict_factors(changes)
    print("rule RD14:", json.dumps(v))
    state = spinup_state(family, law)
    for name, meshes in state.items():
        print(f"{name} spin-up, day 14: " + "; ".join(
            f"{km} km damage {m['mean_damage']:.3f}, bands {m['band_fraction']:.3f}, h {m['mean_thickness_m']:.2f} m, "
            f"A {m['mean_concentration']:.3f}" for km, m in meshes.items()))
    _write_json("factors", {"family": family, "law": law, "against": "spun", "changes": changes, "verdict": v,
                            "spinup_state": state})
    fig = ROOT / "docs" / "figures" / f"disk_month_factors_{family}.png"
    figure_factors(family, law, json.loads(JSON.read_text()), fig)
    print(f"wrote {fig.relative_to(ROOT)}")
    return {"changes": changes, "verdict": v}


#: rule RD15: the 5 km mesh's months (the first two wind seeds of the eight) of RD13's variant
FINE_KM, FINE_SEEDS, FINE_VARIANT = 5.0, (2026, 2027), "meanspun"


def verdict_fine(rows: list) -> dict:
    """Rule RD15 on rows ``{"seed", "beta_5km", "beta_10km", "beta_20km"}``: (w) β at 5 km lower than at 10 km by
    at least 0.015 in every month, (x) higher by at least 0.015 in every month; neither: not told."""
    d = [r["beta_5km"] - r["beta_10km"] for r in rows]
    return {"months": len(rows), "change_5_less_10": d,
            "w_keeps_falling": bool(rows and all(x <= -0.015 for x in d)),
            "x_turns_back": bool(rows and all(x >= 0.015 for x in d))}


def fine(family: str = "lead", law: str = "same_pa", variant: str = FINE_VARIANT) -> dict:
    """Rules RD15 (``meanspun``) and RD17 (``spun``): a variant's months on the :data:`FINE_KM` mesh against the
    same months at 10 and 20 km (from the set's record, written by ``report --stage month``)."""
    rule = "RD15" if variant == FINE_VARIANT else "RD17"
    paths = finished_runs([OUT / run_name(family, law, FINE_KM, sd, "month", variant) for sd in FINE_SEEDS],
                          "fine")
    per = beta_by_seed(json.loads(JSON.read_text())[f"{_month_prefix(variant)}{family}-{law}"]["meshes"])
    pooled = pool_windows({f"{FINE_KM:g}": paths})[f"{FINE_KM:g}"]
    rows = [{"seed": _seed_of(p), "beta_5km": pooled["beta_common_per_run"][p.name],
             "beta_10km": per["10"][_seed_of(p)], "beta_20km": per["20"][_seed_of(p)]} for p in paths]
    for r in rows:
        print(f"wind seed {r['seed']}: β on 20-120 km {r['beta_20km']:.3f} (20 km) {r['beta_10km']:.3f} (10 km) "
              f"{r['beta_5km']:.3f} (5 km)")
    v = verdict_fine(rows)
    print(f"rule {rule}:", json.dumps(v))
    _write_json(f"fine-{variant}", {"family": family, "law": law, "km": FINE_KM, "rule": rule, "months": rows,
                                    "mesh": pooled, "verdict": v})
    return {"months": rows, "verdict": v}


def verdict_realisations(beta_20km: dict) -> dict:
    """Rule RD16 (y): the pooled 20 km β of the realisations of one pack's spin-up (``{variant: β}``) spans at
    least 0.03."""
    span = max(beta_20km.values()) - min(beta_20km.values())
    return {"realisations": len(beta_20km), "span_20km": span, "y_realisation_moves_beta": bool(span >= 0.03)}


def realisations(family: str = "lead", law: str = "same_pa") -> dict:
    """Rule RD16: the pooled 20 km β of RD9's spin-up and of its realisations under the wind seeds of
    :data:`REALISATION_SEEDS`, each over the eight months (the 20 km months only; ``spun``'s from its record)."""
    data = json.loads(JSON.read_text())
    beta, per_run = {"spun": data[f"month-spun-{family}-{law}"]["meshes"]["20"]["beta_common"]}, {}
    for sd in REALISATION_SEEDS:
        v = f"spun{sd}"
        paths = finished_runs([OUT / run_name(family, law, 20, s, "month", v) for s in MONTH_SEEDS], "realisations")
        pooled = pool_windows({v: paths})[v]
        beta[v], per_run[v] = pooled["beta_common"], pooled["beta_common_per_run"]
    v = verdict_realisations(beta)
    for name, b in beta.items():
        print(f"{name}: pooled β on 20-120 km at 20 km {b:.3f}")
    print("rule RD16:", json.dumps(v))
    _write_json("realisations", {"family": family, "law": law, "km": 20, "beta_common_20km": beta,
                                 "beta_common_per_run": per_run, "spinup_state": spinup_state(family, law, list(beta)),
                                 "verdict": v})
    fig = ROOT / "docs" / "figures" / f"disk_month_factors_{family}.png"
    figure_factors(family, law, json.loads(JSON.read_text()), fig)
    print(f"wrote {fig.relative_to(ROOT)}")
    return {"beta_common_20km": beta, "verdict": v}


#: rule RD18: the realisation of RD9's spin-up with the highest 20 km β (RD16), on the 10 km mesh
REALISATION_10KM_VARIANT = "spun2023"


def verdict_realisation_10km(beta_variant: float, beta_spun: float) -> dict:
    """Rule RD18 (z): the pooled 10 km β of a realisation within 0.015 of ``spun``'s (does not follow it), or at
    least 0.02 higher (follows it); else neither."""
    d = beta_variant - beta_spun
    return {"change_10km": d, "z_10km_keeps_its_beta": bool(abs(d) < 0.015), "follows_realisation": bool(d >= 0.02)}


def realisation_10km(family: str = "lead", law: str = "same_pa", variant: str = REALISATION_10KM_VARIANT) -> dict:
    """Rule RD18: ``variant``'s eight months on the 10 km mesh against RD9's (``spun``, from its record), pooled
    and paired by wind seed, beside the same realisation's change at 20 km (RD16's record)."""
    data = json.loads(JSON.read_text())
    paths = finished_runs([OUT / run_name(family, law, 10, s, "month", variant) for s in MONTH_SEEDS],
                          "realisations --km 10")
    pooled = pool_windows({variant: paths})[variant]
    spun = data[f"month-spun-{family}-{law}"]["meshes"]
    base = beta_by_seed(spun)["10"]
    mine = {_seed_of(k): b for k, b in pooled["beta_common_per_run"].items()}
    seeds = sorted(set(mine) & set(base))
    r20 = data["realisations"]["beta_common_20km"]
    v = verdict_realisation_10km(pooled["beta_common"], spun["10"]["beta_common"])
    v["paired_change_10km"] = mean_interval([mine[s] - base[s] for s in seeds])
    v["change_20km"] = r20[variant] - r20["spun"]
    print(f"{variant}: pooled β on 20-120 km at 10 km {pooled['beta_common']:.3f} against spun's "
          f"{spun['10']['beta_common']:.3f} (at 20 km {r20[variant]:.3f} against {r20['spun']:.3f})")
    print("rule RD18:", json.dumps(v))
    _write_json(f"realisation-10km-{variant}", {"family": family, "law": law, "km": 10, "variant": variant,
                                                 "beta_common_per_run": pooled["beta_common_per_run"],
                                                 "beta_common": pooled["beta_common"], "verdict": v})
    return v


def verdict_fragmentation(bins: dict) -> dict:
    """Rule RD7 (k) on :func:`fragmentation`'s bins: the two meshes agree within 0.02 in every bin both fill
    (at least :data:`FRAGMENTATION_MIN_WINDOWS` windows each), and on each mesh β is at least 0.03 lower in
    its most cut filled bin than in its least cut one."""
    n = FRAGMENTATION_MIN_WINDOWS
    coarse, fine = bins["20"], bins["10"]
    shared = [(a["beta_common"], b["beta_common"]) for a, b in zip(coarse, fine)
              if a["n_windows"] >= n and b["n_windows"] >= n]
    drops = {}
    for km, row in bins.items():
        filled = [r["beta_common"] for r in row if r["n_windows"] >= n]
        drops[km] = filled[0] - filled[-1] if len(filled) >= 2 else None
    agree = bool(shared) and all(abs(a - b) < 0.02 for a, b in shared)
    falls = all(d is not None and d >= 0.03 for d in drops.values())
    return {"bins_shared": len(shared), "largest_gap_shared": max((abs(a - b) for a, b in shared), default=None),
            "meshes_agree": agree, "drop_least_to_most_cut": drops, "beta_falls_with_cutting": falls,
            "k_fragmentation_sets_beta": bool(agree and falls)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("run", "report", "basin", "fragmentation", "floes", "healing", "factors", "fine",
                                     "realisations", "thermodynamics", "mechanics", "restoring",
                                     "counted", "moved", "correlated", "banded", "averaged"))
    ap.add_argument("groups", nargs="*", help="basin: NAME=RUN,RUN,... (runs in benchmarks/out/physics)")
    ap.add_argument("--family", choices=sorted(FAMILIES), default="lead")
    ap.add_argument("--law", choices=LAWS, default="same_pa")
    ap.add_argument("--km", type=float, nargs="+", help="meshes (default: 20 14 10 7 5; stage month: 20 10)")
    ap.add_argument("--seeds", type=int, nargs="+", help="seeds (default 12-17; stage month: wind seeds 2026-2033)")
    ap.add_argument("--more-seeds", action="store_true", help="add rule RD2's seeds 18-23")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--stage", choices=("storm", "month"), default="storm",
                    help="storm: one cyclone, 3 days (default); month: examples/winter_disk.toml, 28 days (RD5)")
    ap.add_argument("--variant", choices=sorted(MONTH_VARIANTS), default="",
                    help="stage month: noheal (healing.law = none; rule RD8), nothermo (thermo.enabled = false; "
                         "RD19), mechanics (nor healing, mesh motion or remeshing; RD20), mechheal and mechmove "
                         "(mechanics with healing, or mesh motion and remeshing, back; RD21), spun (from a 14-day "
                         "spin-up; RD9), "
                         "packspun (from a 14-day spin-up of the basin's thick-and-thin pack; RD10), meanspun "
                         "(the same from uniform ice of the pack's means; RD13), thickspun and concspun (its "
                         "thickness alone, its concentration alone; RD14); fine: the spun-up variant "
                         "(default meanspun, RD15; spun, RD17)")
    a = ap.parse_args(argv)
    if a.what == "fragmentation":
        fragmentation(a.family)
        return 0
    if a.what == "floes":
        floes(a.family)
        return 0
    if a.what == "realisations":
        if a.km and a.km != [20.0]:
            if a.km != [10.0]:
                ap.error("realisations: --km 20 (rule RD16, the default) or --km 10 (rule RD18)")
            realisation_10km(a.family, a.law)
        else:
            realisations(a.family, a.law)
        return 0
    if a.what == "fine":
        variant = a.variant or FINE_VARIANT
        if variant not in SPUN_VARIANTS:
            ap.error(f"fine: --variant must be a spun-up variant ({', '.join(SPUN_VARIANTS)}), not {variant!r}")
        fine(a.family, a.law, variant)
        return 0
    if a.what == "factors":
        factors(a.family, a.law)
        return 0
    # the month-set analyses: (function, the wind seeds it reads by default)
    analyses = {"mechanics": (mechanics, MONTH_SEEDS), "restoring": (restoring, MONTH_SEEDS),
                "averaged": (averaged, MORE_MONTH_SEEDS),
                **{name: (fn, MONTH_SEEDS + MORE_MONTH_SEEDS)
                   for name, fn in (("counted", counted), ("banded", banded), ("correlated", correlated),
                                    ("moved", moved), ("thermodynamics", thermodynamics), ("healing", healing))}}
    if a.what in analyses:
        fn, default_seeds = analyses[a.what]
        fn(a.family, a.law, tuple(a.seeds) if a.seeds else default_seeds)
        return 0
    if a.stage == "month" and a.what == "report":
        report_month(a.family, a.law, a.variant, tuple(a.seeds) if a.seeds else MONTH_SEEDS)
        return 0
    if a.what == "run":
        # the finest meshes first, so that two jobs finish together
        if a.stage == "month":
            kms, seeds = a.km or list(MONTH_KM), a.seeds or list(MONTH_SEEDS)
        else:
            kms, seeds = a.km or list(KM), list(a.seeds or SEEDS) + (list(MORE_SEEDS) if a.more_seeds else [])
        todo = [(a.family, a.law, km, s, a.stage, a.variant) for km in sorted(kms) for s in seeds]
        with ThreadPoolExecutor(a.jobs) as ex:
            if a.variant in SPUN_VARIANTS:
                for msg in ex.map(lambda km: make_spinup(a.family, a.law, km, a.variant), sorted(kms)):
                    print(msg, flush=True)
            for msg in ex.map(lambda t: run_one(*t), todo):
                print(msg, flush=True)
        return 0
    if a.what == "basin":
        basin({g.split("=")[0]: g.split("=")[1].split(",") for g in a.groups})
        return 0
    report(a.family, a.law)
    return 0


if __name__ == "__main__":
    sys.exit(main())
