// cloudgen/param_list.h — the one list of user parameters (an X-macro list).
//
// Each row declares one parameter; params.h expands the rows into the enum P
// (the first column) and params.cpp into the table kParams, so the two cannot
// disagree by position. Rows are in declaration order, which is also the slot
// order of Params::values and the order of every listing (CLI, Python, docs).
//
// Columns:
//   CG_PARAM(ENUM, key, label, group, kind, (default...), min, max, soft_min, soft_max, map_lo, map_hi,
//            unit, help)
//   ENUM      the cg::P enumerator
//   key       identifier used in files, dicts and on the command line
//   label     what the artist sees
//   group     "Cloud Main", "Cloud Noise", "Animation" or "Box"
//   kind      Float, Int, Vector or Curve (cg::Kind)
//   default   in parentheses: one value, three for a vector; a curve's default is kDefaultCurve
//   min, max  hard limits: anything outside is refused at the API boundary
//   soft_*    slider range
//   map_*     physical = map_lo + (map_hi - map_lo) * value (0, 1 = identity)
//
// Include this file only after defining CG_PARAM; it undefines nothing.
//
// clang-format off
CG_PARAM(CLOUD_SCALE, "cloud_scale", "Cloud Scale", "Cloud Main", Float, (0.85f), 0.05f, 1.0f, 0.05f, 1.0f, 0, 1,
         "fraction of the box",
         "Size of the cloud inside its box: 1 touches the box faces, smaller values shrink it about the centre.")
// Density's slider reaches 8, not 1: real cumulus (liquid water 0.5-2 g/m^3, droplets ~10 um)
// have an extinction of 70-300 per km, 1-4 on this slider at 250 m per unit, and the heap presets
// sit at 4.5-6 (denser than that in their core, for a surface as sharp as a real cloud's: docs/model.md).
CG_PARAM(DENSITY, "density", "Density", "Cloud Main", Float, (0.5f), 0.0f, 10.0f, 0.0f, 8.0f, 0, CG_DENSITY_SCALE,
         "slider (x20 per scene unit)",
         "Density handed to the volume shader: the physical density is 20 x this value x the shape density "
         "(about 1 in the cloud's core).")
CG_PARAM(DISTORTION, "distortion", "Distortion", "Cloud Main", Float, (0.7f), 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
         "", "How strongly the Cloud Noise texture distorts the shape (F in eq. 3.4).")
CG_PARAM(SHAPE_MODE, "shape_mode", "Shape Source", "Cloud Main", Int, (0), 0, 1, 0, 1, 0, 1,
         "0 exponent, 1 curve",
         "Where the height profile comes from: 0 the Shape Exponent, 1 the Shape Gradient curve.")
CG_PARAM(SHAPE_EXPONENT, "shape_exponent", "Shape Exponent", "Cloud Main", Float, (0.6f), 0.05f, 20.0f, 0.1f, 4.0f,
         0, 1, "",
         "Height-profile exponent e in S = 1 - (2 h^e - 1)^2: below 1 a flat base and a dome, above 1 a wide top.")
CG_PARAM(SHAPE_CURVE, "shape_curve", "Shape Gradient", "Cloud Main", Curve, (0), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
         "squared radius",
         "Height profile as 17 samples at heights 0, 1/16, ..., 1 (used when Shape Source is 1).")
CG_PARAM(EDGE_SHARPNESS, "edge_sharpness", "Edge Sharpness", "Cloud Main", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f,
         0, 1, "", "How fast the density rises at the cloud's boundary: 0 the thesis's soft ramp, 1 a crisp edge "
         "(wisps only where the noise erodes).")
CG_PARAM(BASE_HEIGHT, "base_height", "Base Height", "Cloud Main", Float, (-0.5f), -0.5f, 1.0f, -0.5f, 1.0f, 0, 1,
         "fraction of the cloud's height",
         "Flat floor: no cloud below this height, the profile held at its value here (a flat condensation base); "
         "-0.5 none.")
CG_PARAM(TOP_HEIGHT, "top_height", "Top Height", "Cloud Main", Float, (1.5f), 0.0f, 1.5f, 0.0f, 1.5f, 0, 1,
         "fraction of the cloud's height",
         "Flat ceiling: no cloud above this height, the profile held at its value here (an anvil's top); 1.5 none.")
CG_PARAM(LEAN, "lean", "Lean", "Cloud Main", Float, (0.0f), -2.0f, 2.0f, -1.0f, 1.0f, 0, 1, "fraction of the width",
         "Shifts the shape along +x with the square of the height: the top leans downwind by this much.")
CG_PARAM(SHEET, "sheet", "Sheet", "Cloud Main", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1, "",
         "1 makes a layer: no round outline, the sheet fills the box and fades out near its sides; 0 a single "
         "cloud.")
CG_PARAM(ANVIL, "anvil", "Anvil", "Cloud Main", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1, "",
         "Spreads the top into an anvil: below Anvil Height the shape is narrowed 1 + 4 x this times, so the "
         "ceiling is up to 5 times as wide as the tower under it; from Anvil Height up the billows calm and the "
         "edge softens, a thin anvil fading toward its rim; 0 none.")
CG_PARAM(ANVIL_HEIGHT, "anvil_height", "Anvil Height", "Cloud Main", Float, (0.75f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
         "fraction of the cloud's height",
         "Where the anvil starts to spread: from here to the ceiling (Top Height, or the top) the tower widens "
         "into the anvil.")
CG_PARAM(ANVIL_FIBRES, "anvil_fibres", "Anvil Fibres", "Cloud Main", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
         "", "Breaks the anvil's rim into streaks of ice (thin sheets running out from the tower); its flat top and "
         "middle stay smooth. For a storm seen from afar: close by, from below, the streaks look smeared. Acts only "
         "with Anvil; 0 a smooth anvil.")
CG_PARAM(OVERALL_SCALE, "overall_scale", "Overall Scale", "Cloud Noise", Float, (1.0f), 0.01f, 20.0f, 0.1f, 4.0f,
         0, 1, "", "Scales the whole texture: larger values give smaller, more numerous features.")
CG_PARAM(WORLEY_INFLUENCE, "worley_influence", "Worley Influence", "Cloud Noise", Float, (0.8f), 0.0f, 1.0f, 0.0f,
         1.0f, 0, 1, "", "Weight of the Worley (billow) component.")
CG_PARAM(WORLEY_CLUMP, "worley_clump", "Worley Clump", "Cloud Noise", Float, (0.5f), 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
         "gain", "Gain of the Worley fBm: higher values add smaller billows on the large ones.")
CG_PARAM(WAVE, "wave", "Wave", "Cloud Noise", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
         "", "Mixes a sine texture into the Worley component for wave-like banding (cirrus).")
CG_PARAM(NOISE_INFLUENCE, "noise_influence", "Noise Influence", "Cloud Noise", Float, (0.6f), 0.0f, 1.0f, 0.0f,
         1.0f, 0, 1, "", "Weight of the gradient-noise fBm (fine detail, frayed edges).")
CG_PARAM(NOISE_SCALE, "noise_scale", "Noise Scale", "Cloud Noise", Float, (1.0f), 0.01f, 20.0f, 0.1f, 4.0f, 0, 1,
         "", "Extra scale of the gradient-noise fBm relative to the Worley texture.")
CG_PARAM(NOISE_DETAIL, "noise_detail", "Noise Detail", "Cloud Noise", Float, (5.0f), 0.0f, 16.0f, 1.0f, 12.0f, 0, 1,
         "octaves", "Octaves of the gradient-noise fBm; a fractional part fades the last octave in.")
CG_PARAM(NOISE_WHISP, "noise_whisp", "Noise Whisp", "Cloud Noise", Float, (0.5f), 0.0f, 2.0f, 0.0f, 1.0f, 0, 1,
         "gain", "Gain of the gradient-noise fBm: higher values give wispier, finer detail.")
CG_PARAM(FIBRES, "fibres", "Fibres", "Cloud Noise", Float, (0.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1, "",
         "Turns the gradient noise into thin fibres along its zero set (with Stretch: cirrus filaments); acts "
         "through Noise Influence.")
CG_PARAM(TURRET_INFLUENCE, "turret_influence", "Turret Influence", "Cloud Noise", Float, (0.0f), 0.0f, 1.0f, 0.0f,
         1.0f, 0, 1, "", "Weight of large Worley turrets under the billows (towers, big lobes).")
CG_PARAM(TURRET_SCALE, "turret_scale", "Turret Size", "Cloud Noise", Float, (3.0f), 1.0f, 16.0f, 1.0f, 8.0f, 0, 1,
         "Worley cells", "Size of a turret in Worley cells (turret cells are twice as tall as wide).")
CG_PARAM(STRETCH, "stretch", "Stretch", "Cloud Noise", Float, (0.0f), 0.0f, 50.0f, 0.0f, 20.0f, 0, 1, "",
         "Stretches the texture along the box's x axis by 1 + this: fibres and streaks.")
CG_PARAM(SHEAR, "shear", "Shear", "Cloud Noise", Float, (0.0f), -10.0f, 10.0f, -2.0f, 2.0f, 0, 1,
         "x shift per unit of height", "Slants the texture along x with height: fall streaks, hooks, sheared tops.")
CG_PARAM(WARP, "warp", "Warp", "Cloud Noise", Float, (0.0f), 0.0f, 4.0f, 0.0f, 1.0f, 0, 1, "warp cells",
         "Bends the whole texture with a large, smooth noise: curved fibres and hooks, irregular billows (the "
         "displacement in warp cells).")
CG_PARAM(WARP_SCALE, "warp_scale", "Warp Size", "Cloud Noise", Float, (8.0f), 1.0f, 64.0f, 1.0f, 32.0f, 0, 1,
         "Worley cells", "Size of a warp cell in Worley cells: how far apart the bends are.")
CG_PARAM(SEED, "seed", "Seed", "Cloud Noise", Int, (0), 0, 1000000, 0, 1000, 0, 1,
         "", "Variation: a different seed gives a different cloud of the same kind.")
CG_PARAM(WIND_STRENGTH, "wind_strength", "Wind Strength", "Animation", Float, (0.0f), 0.0f, 100.0f, 0.0f, 1.0f, 0, 1,
         "scene units per second", "Speed at which the texture drifts along the wind direction.")
CG_PARAM(WIND_DIRECTION, "wind_direction", "Wind Direction", "Animation", Vector, (1.0f, 0.0f, 0.0f), -1.0f, 1.0f,
         -1.0f, 1.0f, 0, 1, "direction", "Direction of the drift (normalised; zero means no drift).")
CG_PARAM(STATIONARY, "stationary", "Stationary", "Animation", Float, (1.0f), 0.0f, 1.0f, 0.0f, 1.0f, 0, 1,
         "", "How much the texture follows the object: 1 moves with it, 0 stays fixed in the world.")
CG_PARAM(TIME, "time", "Time", "Animation", Float, (0.0f), -1.0e6f, 1.0e6f, 0.0f, 250.0f, 0, 1,
         "seconds", "Time in seconds: drives wind drift and evolution.")
CG_PARAM(EVOLUTION, "evolution", "Evolution", "Animation", Float, (0.1f), 0.0f, 10.0f, 0.0f, 1.0f, 0, 1,
         "noise cells per second", "Speed of the shape change that is not drift (the fourth noise dimension).")
CG_PARAM(BOX_SIZE, "box_size", "Box Size", "Box", Vector, (2.0f, 2.0f, 2.0f), 0.001f, 1.0e5f, 0.1f, 100.0f, 0, 1,
         "scene units", "Dimensions of the cloud box (the object's scale included).")
CG_PARAM(OBJECT_LOCATION, "object_location", "Object Location", "Box", Vector, (0.0f, 0.0f, 0.0f), -1.0e7f, 1.0e7f,
         -100.0f, 100.0f, 0, 1, "scene units", "World location of the cloud object (used by Stationary).")
// clang-format on
