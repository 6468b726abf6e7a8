# hovering_sweep end to end on quick scenes of both kinds: rows, values, resume keyed by every
# parameter, torn rows, foreign headers, scene errors with Python's messages, bad options.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(csv "${WORK}/trunc.csv")

# A truncated-map sweep: the paper's map (Omega_G, theta_w = 3 pi / 4) at eps = +-0.2, quick
# (n_steps 5000 / 50 = 100 steps, samples 20000 / 50 = 400).
set(trunc_scene [=[
kind = "hovering_area"
output = "out/trunc.png"
n_steps = 5000
samples = 20000
eps = [0.2, -0.2]
[map]
Omega0 = "OMEGA_G"
theta_w = "3*pi/4"
[[series]]
label = "paper"
]=])
file(WRITE "${WORK}/trunc.toml" "${trunc_scene}")

# Field i (from 0) of a CSV line.
function(field line i out)
  string(REPLACE "," ";" f "${line}")
  list(GET f ${i} v)
  set(${out} "${v}" PARENT_SCOPE)
endfunction()

# Index of a column in the header line.
function(column header name out)
  string(REPLACE "," ";" f "${header}")
  list(FIND f "${name}" i)
  if(i LESS 0)
    message(FATAL_ERROR "no column ${name} in ${header}")
  endif()
  set(${out} ${i} PARENT_SCOPE)
endfunction()

# The lines of a CSV that are not comments (the header and the rows).
macro(read_csv file)
  file(STRINGS "${file}" lines REGEX "^[^#]")
  list(LENGTH lines n)
endmacro()

macro(sweep)
  execute_process(COMMAND ${SWEEP} ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
endmacro()

sweep(--scene ${WORK}/trunc.toml --quick --out ${csv} --threads 2)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sweep failed (${rc}): ${err}")
endif()
read_csv(${csv})
if(NOT n EQUAL 3)
  message(FATAL_ERROR "expected header + 2 rows, got ${n}: ${lines}")
endif()
list(GET lines 0 head)
list(GET lines 1 pos)
list(GET lines 2 neg)
foreach(c area error theory n_samples K_low eps Omega0 theta_w n_steps samples seed seconds)
  column("${head}" ${c} i_${c})
endforeach()
field("${pos}" ${i_area} a_pos)
field("${pos}" ${i_error} e_pos)
field("${pos}" ${i_theory} t_pos)
field("${neg}" ${i_area} a_neg)
field("${neg}" ${i_theory} t_neg)
field("${pos}" ${i_n_steps} steps)
field("${pos}" ${i_samples} samples)
field("${pos}" ${i_Omega0} om)
field("${pos}" ${i_theta_w} tw)
field("${pos}" ${i_K_low} klow)
# thm:hovering: a hovering set for eps = +0.2 (eq:hovsetsize: 0.509), none for eps = -0.2. The
# quick estimate (400 samples, 100 steps) lies within 0.1 of it; exactly 0 below.
if(NOT (a_pos GREATER 0.4 AND a_pos LESS 0.62 AND e_pos GREATER 0 AND a_neg EQUAL 0 AND t_neg EQUAL 0
        AND t_pos GREATER 0.509 AND t_pos LESS 0.51))
  message(FATAL_ERROR "unexpected areas: +0.2: ${a_pos} +- ${e_pos} (theory ${t_pos}); -0.2: ${a_neg} (theory ${t_neg})")
endif()
# The parameters as evaluated (expressions of the scene) and the quick counts; Python's default box
# -2 eps / sin(Omega_G / 2) to the last digit.
if(NOT (steps EQUAL 100 AND samples EQUAL 400 AND om STREQUAL "3.883222077450933" AND tw STREQUAL "2.356194490192345"
        AND klow STREQUAL "-0.429169618760127"))
  message(FATAL_ERROR "row parameters: n_steps ${steps} samples ${samples} Omega0 ${om} theta_w ${tw} K_low ${klow}")
endif()

# Provenance: the file starts with one comment line of JSON, the core's build facts and the run's
# threads and seed (the values are checked against Python's record in tests/test_atomic_outputs.py).
file(STRINGS "${csv}" comments REGEX "^#")
list(LENGTH comments n_comments)
file(STRINGS "${csv}" first LIMIT_COUNT 1)
if(NOT n_comments EQUAL 1 OR NOT first MATCHES "^# provenance: {\"hovering\": \"[0-9.]+\", \"git\": "
   OR NOT first MATCHES "\"gsl\": " OR NOT first MATCHES "\"eigen\": " OR NOT first MATCHES "\"sleef\": "
   OR NOT first MATCHES "\"compiler\": " OR NOT first MATCHES "\"simd_width\": [1248]," OR NOT first MATCHES "\"platform\": "
   OR NOT first MATCHES "\"threads\": 2, \"seed\": 0}$")
  message(FATAL_ERROR "provenance comment missing or incomplete (${n_comments} comments): ${first}")
endif()

# Rerun: both points are in the file, nothing is computed or appended.
sweep(--scene ${WORK}/trunc.toml --quick --out ${csv} --threads 1)
read_csv(${csv})
if(NOT rc EQUAL 0 OR NOT n EQUAL 3 OR NOT err MATCHES "2 already in")
  message(FATAL_ERROR "resume failed (${rc}, ${n} lines): ${err}")
endif()

# A new eps and a changed parameter: only the points with new parameters are computed.
string(REPLACE "eps = [0.2, -0.2]" "eps = [0.2, -0.2, 0.1]" scene2 "${trunc_scene}")
file(WRITE "${WORK}/trunc2.toml" "${scene2}")
sweep(--scene ${WORK}/trunc2.toml --quick --out ${csv})
read_csv(${csv})
if(NOT rc EQUAL 0 OR NOT n EQUAL 4 OR NOT err MATCHES "2 already in")
  message(FATAL_ERROR "new eps not appended alone (${rc}, ${n} lines): ${err}")
endif()
# Any parameter that changes the numbers makes new rows: the seed, the sample count, a map parameter.
string(REPLACE "samples = 20000" "samples = 30000" v_samples "${trunc_scene}")
string(REPLACE "[map]\n" "[map]\ntau1 = 0.4\n" v_tau1 "${trunc_scene}")
foreach(variant "seed = 1\n${trunc_scene}" "${v_samples}" "${v_tau1}")
  file(WRITE "${WORK}/trunc3.toml" "${variant}")
  read_csv(${csv})
  set(before ${n})
  sweep(--scene ${WORK}/trunc3.toml --quick --out ${csv})
  read_csv(${csv})
  math(EXPR want "${before} + 2")
  if(NOT rc EQUAL 0 OR NOT n EQUAL want)
    message(FATAL_ERROR "a changed parameter did not recompute both points (${rc}, ${n} lines, want ${want}): ${err}\n${variant}")
  endif()
endforeach()

# A row torn by a kill (no newline) is dropped and recomputed, not counted as done.
read_csv(${csv})
list(GET lines -1 last)
file(READ "${csv}" text)
string(REGEX REPLACE "\n[^\n]*\n$" "\n" text "${text}")
string(SUBSTRING "${last}" 0 20 torn)
file(WRITE "${csv}" "${text}${torn}")
sweep(--scene ${WORK}/trunc3.toml --quick --out ${csv})
read_csv(${csv})
list(GET lines -1 last2)
# The recomputed row is the dropped one, digit for digit, but for its timing.
string(REPLACE "," ";" f1 "${last}")
string(REPLACE "," ";" f2 "${last2}")
list(REMOVE_AT f1 ${i_seconds})
list(REMOVE_AT f2 ${i_seconds})
if(NOT rc EQUAL 0 OR NOT err MATCHES "dropped a torn row" OR NOT n EQUAL want OR NOT f1 STREQUAL f2)
  message(FATAL_ERROR "torn row not recomputed (${rc}, ${n} lines, last '${last2}' vs '${last}'): ${err}")
endif()

# A damaged line with rows after it is refused and the file left alone.
file(WRITE "${WORK}/mid.csv" "${head}\n0.5,1,2\n${last}\n")
file(READ "${WORK}/mid.csv" before)
sweep(--scene ${WORK}/trunc.toml --quick --out ${WORK}/mid.csv)
file(READ "${WORK}/mid.csv" after)
if(rc EQUAL 0 OR NOT err MATCHES "line 2 is not a valid row" OR NOT after STREQUAL before)
  message(FATAL_ERROR "damaged file not refused (${rc}): ${err}")
endif()

# Another kind's (or an older version's) file is refused untouched.
file(WRITE "${WORK}/old.csv" "eps,n_orbits,never_impact\n0.2,1200,239\n")
file(READ "${WORK}/old.csv" before)
sweep(--scene ${WORK}/trunc.toml --quick --out ${WORK}/old.csv)
file(READ "${WORK}/old.csv" after)
if(rc EQUAL 0 OR NOT err MATCHES "does not have the header" OR NOT after STREQUAL before)
  message(FATAL_ERROR "foreign header not refused (${rc}): ${err}")
endif()

# The flow: |HOV| of the full flow at eps = -0.1 and 0.1 on a quick scene (50 returns, 100 samples).
file(WRITE "${WORK}/flow.toml" [=[
kind = "flow_hovering_area"
output = "out/flow.png"
n_steps = 2000
samples = 2000
eps = [-0.1, 0.1]
models = ["onset"]
[system]
V1 = { kind = "harmonic", omega = 1.0 }
V2 = { kind = "tan", omega = 1.4, alpha = 0.7 }
qw1 = -1.0
qw2 = -0.5
[section]
h = 1.0
]=])
sweep(--scene ${WORK}/flow.toml --quick --out ${WORK}/flow.csv)
read_csv(${WORK}/flow.csv)
if(NOT rc EQUAL 0 OR NOT n EQUAL 3)
  message(FATAL_ERROR "flow sweep failed (${rc}, ${n} lines): ${err}")
endif()
list(GET lines 0 fhead)
list(GET lines 1 fneg)
foreach(c area error theory unresolved onset_area onset_agree n_samples)
  column("${fhead}" ${c} j_${c})
endforeach()
field("${fneg}" ${j_area} fa)
field("${fneg}" ${j_theory} ft)
field("${fneg}" ${j_onset_agree} fagree)
field("${fneg}" ${j_unresolved} fun)
field("${fneg}" ${j_n_samples} fns)
# This system hovers for eps < 0 (its measured b_1 sin(Omega0 / 2) < 0): the flow's |HOV| at
# eps = -0.1 is near eq:hovsetsize's 0.151 and the onset model classifies >= 90% of the points alike.
if(NOT (fa GREATER 0.05 AND fa LESS 0.3 AND ft GREATER 0.14 AND ft LESS 0.16 AND fagree GREATER 0.9 AND fun EQUAL 0
        AND fns GREATER 99))
  message(FATAL_ERROR "flow row: area ${fa} theory ${ft} agree ${fagree} unresolved ${fun} samples ${fns}")
endif()
sweep(--scene ${WORK}/flow.toml --quick --out ${WORK}/flow.csv)
if(NOT rc EQUAL 0 OR NOT err MATCHES "2 already in")
  message(FATAL_ERROR "flow resume failed (${rc}): ${err}")
endif()
# A flow file is not a truncated sweep's file.
sweep(--scene ${WORK}/trunc.toml --quick --out ${WORK}/flow.csv)
if(rc EQUAL 0 OR NOT err MATCHES "does not have the header")
  message(FATAL_ERROR "a truncated sweep appended to a flow file (${rc}): ${err}")
endif()

# Scene errors: Python's messages, before any file is touched.
# (Brackets in TOML would split CMake lists: one call per case.)
function(bad_scene text want)
  file(WRITE "${WORK}/bad.toml" "${text}")
  execute_process(COMMAND ${SWEEP} --scene ${WORK}/bad.toml --out ${WORK}/bad.csv RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "${want}" OR EXISTS "${WORK}/bad.csv")
    message(FATAL_ERROR "scene error not reported as Python does (${rc}): ${err}\nwanted: ${want}")
  endif()
endfunction()
set(head_trunc "kind = \"hovering_area\"\noutput = \"a.png\"\nn_steps = 10\neps = [0.1]\n")
bad_scene("${head_trunc}steps = 3\n[[series]]\nlabel = \"x\"\nOmega0 = 1\ntheta_w = 1\n"
          "bad.toml: unknown key\\(s\\) 'steps'; allowed keys: kind, title, output, dpi, figsize, map, n_steps, samples, seed, eps, series")
bad_scene("kind = \"portrait\"\noutput = \"a.png\"\nn_steps = 10\n" "bad.toml.kind = 'portrait': hovering_sweep runs the sweep kinds")
bad_scene("${head_trunc}[[series]]\nlabel = \"x\"\nOmega0 = \"2**\"\ntheta_w = 1\n" "bad.toml.series.0..Omega0: cannot evaluate '2..'")
bad_scene("${head_trunc}[[series]]\nlabel = \"x\"\nOmega0 = 1\ntheta_w = 4\n"
          "bad.toml.series.0..theta_w = 4 is out of range; allowed: .0.0, 3.141592653589793.")
bad_scene("kind = \"flow_hovering_area\"\noutput = \"a.png\"\nn_steps = 10\neps = [0.1]\n[system]\nV1 = { kind = \"harmonic\", omega = 1.0 }\nV2 = { kind = \"tan\", omega = 1.4, alpha = 0.7 }\n[integrator]\nacuracy = 1e-9\n"
          "bad.toml.integrator: unknown key\\(s\\) 'acuracy'")

# An accuracy target needs Python's measurement: refused with what to do instead.
file(READ "${WORK}/flow.toml" ft)
file(WRITE "${WORK}/acc.toml" "${ft}[integrator]\naccuracy = 1e-9\n")
sweep(--scene ${WORK}/acc.toml --out ${WORK}/acc.csv)
if(NOT rc EQUAL 2 OR NOT err MATCHES "give stepper and rtol instead" OR EXISTS "${WORK}/acc.csv")
  message(FATAL_ERROR "accuracy target not refused (${rc}): ${err}")
endif()

# Bad options: CLI11's messages name the option.
foreach(args "--scene;${WORK}/missing.toml" "--scene;${WORK}/trunc.toml;--threads;-1" "--scene;${WORK}/trunc.toml;--bogus"
             "--quick" "--scene;${WORK}/trunc.toml;--out;${WORK}/nodir/x.csv" "--scene;${WORK}/trunc.toml;--out;${WORK}")
  sweep(${args})
  if(NOT rc EQUAL 2 OR err STREQUAL "")
    message(FATAL_ERROR "bad options '${args}' not refused with a message (${rc}): ${err}")
  endif()
endforeach()
sweep(--help)
if(NOT rc EQUAL 0 OR NOT out MATCHES "--scene" OR NOT out MATCHES "--quick")
  message(FATAL_ERROR "--help (${rc}): ${out}")
endif()
message(STATUS "hovering_sweep end to end: ok")
