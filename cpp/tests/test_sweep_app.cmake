# Runs hovering_sweep on a tiny grid and checks its CSV: rows, values, resume keyed by every
# parameter, torn rows, foreign headers, and errors that leave the file alone.
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
set(csv "${WORK}/sweep.csv")
set(common --grid 60,20 --steps 400 --K-range -0.4,0 --threads 2 --out ${csv})
set(header "eps,n_orbits,never_impact,impact,escaped,area_never_impact,box_area,theory_eq_hovsetsize,steps,Omega0,theta_w,tau0,tau1,lam,K_lo,K_hi,n_phi,n_K")

# Field i (from 0) of a CSV line.
function(field line i out)
  string(REPLACE "," ";" f "${line}")
  list(GET f ${i} v)
  set(${out} "${v}" PARENT_SCOPE)
endfunction()

# Lines of the CSV (header included) into n and lines.
macro(read_csv)
  file(STRINGS "${csv}" lines)
  list(LENGTH lines n)
endmacro()

execute_process(COMMAND ${SWEEP} --eps 0.2,-0.2 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "sweep failed (${rc}): ${err}")
endif()
read_csv()
if(NOT n EQUAL 3)
  message(FATAL_ERROR "expected header + 2 rows, got ${n}: ${lines}")
endif()
list(GET lines 0 head)
if(NOT head STREQUAL header)
  message(FATAL_ERROR "header is\n  ${head}\nexpected\n  ${header}")
endif()
list(GET lines 1 pos)
list(GET lines 2 neg)
set(first_row "${pos}")
field("${pos}" 2 never_pos)
field("${neg}" 2 never_neg)
field("${pos}" 1 norb)
# thm:hovering: orbits that never impact exist for eps = +0.2 (about 0.5/2.5 of this box), none
# for eps = -0.2; 1200 orbits per eps.
if(NOT norb EQUAL 1200 OR never_pos LESS 150 OR NOT never_neg EQUAL 0)
  message(FATAL_ERROR "unexpected counts: n=${norb} never(+0.2)=${never_pos} never(-0.2)=${never_neg}")
endif()
# Every input of the row is written, the map's defaults included (Omega0 = pi (sqrt 5 - 1)).
string(REPLACE "," ";" f "${pos}")
list(SUBLIST f 8 10 key)
if(NOT key STREQUAL "400;3.883222077450933;2.356194490192345;1;0.5;0.5;-0.4;0;60;20")
  message(FATAL_ERROR "row parameters (steps..n_K) are ${key}")
endif()

# Rerun with one new eps: the two finished ones are skipped, one row is appended.
execute_process(COMMAND ${SWEEP} --eps 0.2,-0.2,0.1 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
read_csv()
if(NOT rc EQUAL 0 OR NOT n EQUAL 4 OR NOT err MATCHES "already in")
  message(FATAL_ERROR "resume failed (${rc}, ${n} lines): ${err}")
endif()

# A repeated eps is computed once.
execute_process(COMMAND ${SWEEP} --eps 0.05,0.05 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
read_csv()
if(NOT rc EQUAL 0 OR NOT n EQUAL 5 OR NOT err MATCHES "eps = 0.05 is listed more than once")
  message(FATAL_ERROR "repeated eps not computed once (${rc}, ${n} lines): ${err}")
endif()

# The same point with another thread count and the K box spelled differently is the same result:
# keys are compared as numbers, and the thread count is not part of them.
execute_process(COMMAND ${SWEEP} --eps 0.2 ${common} --threads 1 --K-range -0.40,0.0 RESULT_VARIABLE rc ERROR_VARIABLE err)
read_csv()
if(NOT rc EQUAL 0 OR NOT n EQUAL 5 OR NOT err MATCHES "eps = 0.2: already in")
  message(FATAL_ERROR "same point not resumed (${rc}, ${n} lines): ${err}")
endif()

# Any other input makes another result: each appends its own row (written with that value), and
# the rows already there stay as they were.
set(changes "--steps|300|8|300" "--Omega0|3.8|9|3.8" "--theta_w|2.3|10|2.3" "--tau0|0.9|11|0.9"
            "--tau1|0.4|12|0.4" "--lam|0.6|13|0.6" "--K-range|-0.3,0|14|-0.3" "--K-range|-0.4,-0.1|15|-0.1"
            "--grid|30,20|16|30" "--grid|60,10|17|10")
set(expect 5)
foreach(c IN LISTS changes)
  string(REPLACE "|" ";" c "${c}")
  list(GET c 0 opt)
  list(GET c 1 val)
  list(GET c 2 col)
  list(GET c 3 written)
  execute_process(COMMAND ${SWEEP} --eps 0.2 ${common} ${opt} ${val} RESULT_VARIABLE rc ERROR_VARIABLE err)
  math(EXPR expect "${expect} + 1")
  read_csv()
  list(GET lines -1 last)
  field("${last}" ${col} got)
  list(GET lines 1 row1)
  if(NOT rc EQUAL 0 OR NOT n EQUAL expect OR err MATCHES "already in" OR NOT got STREQUAL written
     OR NOT row1 STREQUAL first_row)
    message(FATAL_ERROR "${opt} ${val} did not append its own row (${rc}, ${n} lines, column ${col} = '${got}'): ${err}")
  endif()
  # And a rerun of that point is now a resume.
  execute_process(COMMAND ${SWEEP} --eps 0.2 ${common} ${opt} ${val} RESULT_VARIABLE rc ERROR_VARIABLE err)
  read_csv()
  if(NOT rc EQUAL 0 OR NOT n EQUAL expect OR NOT err MATCHES "already in")
    message(FATAL_ERROR "${opt} ${val}: rerun not resumed (${rc}, ${n} lines): ${err}")
  endif()
endforeach()

# A row torn by a kill (no newline) is dropped, not counted as done nor glued to the next row,
# and its point is recomputed.
file(APPEND "${csv}" "0.3,1200,5")
execute_process(COMMAND ${SWEEP} --eps 0.3 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
read_csv()
math(EXPR expect "${expect} + 1")
list(GET lines -1 last)
string(REPLACE "," ";" f "${last}")
list(LENGTH f nf)
file(READ "${csv}" text)
if(NOT rc EQUAL 0 OR NOT n EQUAL expect OR NOT err MATCHES "dropped a torn row" OR NOT last MATCHES "^0\\.3,1200,"
   OR NOT nf EQUAL 18 OR NOT text MATCHES "\n$" OR text MATCHES "0\\.3,1200,50\\.3")
  message(FATAL_ERROR "torn row (no newline) not handled (${rc}, ${n} lines, last '${last}'): ${err}")
endif()
# Torn inside the last field, a row still has 18 numbers ("...,60,2" from "...,60,20"), but without
# its newline it is not done: --grid 60,2 must compute its own row, not resume from the torn one.
file(READ "${csv}" before)
string(REGEX REPLACE "0$" "" torn "${last}")
file(APPEND "${csv}" "${torn}")
execute_process(COMMAND ${SWEEP} --eps 0.3 ${common} --grid 60,2 RESULT_VARIABLE rc ERROR_VARIABLE err)
read_csv()
list(GET lines -1 last2)
field("${last2}" 1 norb)
file(READ "${csv}" after)
if(NOT rc EQUAL 0 OR err MATCHES "already in" OR NOT err MATCHES "dropped a torn row.*no newline" OR NOT norb EQUAL 120
   OR NOT after STREQUAL "${before}${last2}\n")
  message(FATAL_ERROR "row torn in its last field not recomputed (${rc}, last '${last2}'): ${err}")
endif()
math(EXPR expect "${expect} + 1")
# A complete last line that is not a row (wrong field count) is dropped too, even when nothing is computed.
file(READ "${csv}" before)
file(APPEND "${csv}" "0.35,1200,7\n")
execute_process(COMMAND ${SWEEP} --eps 0.3 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ "${csv}" after)
if(NOT rc EQUAL 0 OR NOT after STREQUAL before OR NOT err MATCHES "dropped a torn row.*3 fields, expected 18"
   OR NOT err MATCHES "eps = 0.3: already in")
  message(FATAL_ERROR "invalid last line not dropped (${rc}): ${err}")
endif()
# ... and one with an unparsable number in a numeric column.
string(REPLACE "0.3,1200," "0.3,12x0," bad_last "${last}")
file(APPEND "${csv}" "${bad_last}\n")
execute_process(COMMAND ${SWEEP} --eps 0.3 ${common} RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ "${csv}" after)
if(NOT rc EQUAL 0 OR NOT after STREQUAL before OR NOT err MATCHES "field 2 \\('12x0'\\) is not a number")
  message(FATAL_ERROR "unparsable last line not dropped (${rc}): ${err}")
endif()
# A damaged line with rows after it is no torn row: refused, the file left alone.
file(WRITE "${WORK}/mid.csv" "${header}\n0.5,1,2\n${last}\n")
file(READ "${WORK}/mid.csv" mid_before)
execute_process(COMMAND ${SWEEP} --eps 0.3 --grid 60,20 --steps 400 --K-range -0.4,0 --out ${WORK}/mid.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ "${WORK}/mid.csv" mid_after)
if(NOT rc EQUAL 2 OR NOT err MATCHES "mid.csv line 2 is not a valid row" OR NOT mid_after STREQUAL mid_before)
  message(FATAL_ERROR "damaged middle line not refused (${rc}): ${err}")
endif()
# A header torn by a kill is rewritten.
file(WRITE "${WORK}/torn_header.csv" "eps,n_orbits,nev")
execute_process(COMMAND ${SWEEP} --eps 0.2 --grid 10,10 --steps 10 --out ${WORK}/torn_header.csv
                RESULT_VARIABLE rc ERROR_VARIABLE err)
file(STRINGS "${WORK}/torn_header.csv" th)
list(LENGTH th nth)
list(GET th 0 th0)
if(NOT rc EQUAL 0 OR NOT nth EQUAL 2 OR NOT th0 STREQUAL header)
  message(FATAL_ERROR "torn header not rewritten (${rc}, ${nth} lines): ${err}")
endif()

# A file with another header (an older version's, or someone else's) is refused untouched.
set(old_header "eps,n_orbits,never_impact,impact,escaped,area_never_impact,box_area,theory_eq_hovsetsize,steps")
file(WRITE "${WORK}/old.csv" "${old_header}\n0.2,1200,239,961,0,0.5005604295,2.513274123,0.5092500695,400\n")
file(READ "${WORK}/old.csv" old_before)
execute_process(COMMAND ${SWEEP} --eps 0.2 ${common} --out ${WORK}/old.csv RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ "${WORK}/old.csv" old_after)
if(NOT rc EQUAL 2 OR NOT old_after STREQUAL old_before
   OR NOT err MATCHES "old.csv does not have the header this version"
   OR NOT err MATCHES "missing columns Omega0,theta_w,tau0,tau1,lam,K_lo,K_hi,n_phi,n_K")
  message(FATAL_ERROR "old-format file not refused (${rc}): ${err}")
endif()
file(WRITE "${WORK}/foreign.csv" "a,b\n1,2\n")
execute_process(COMMAND ${SWEEP} --eps 0.2 ${common} --out ${WORK}/foreign.csv RESULT_VARIABLE rc ERROR_VARIABLE err)
file(READ "${WORK}/foreign.csv" foreign_after)
if(NOT rc EQUAL 2 OR NOT foreign_after STREQUAL "a,b\n1,2\n" OR NOT err MATCHES "columns this version does not write a,b")
  message(FATAL_ERROR "foreign file not refused (${rc}): ${err}")
endif()

# Bad input: a clear message naming the option, the value and the allowed range, exit status 2,
# before anything is computed or written: no new file, an existing one unchanged.
file(READ "${csv}" before)
function(expect_usage_error regex)
  execute_process(COMMAND ${SWEEP} ${ARGN} --out ${WORK}/x.csv RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(NOT rc EQUAL 2 OR NOT err MATCHES "${regex}" OR EXISTS "${WORK}/x.csv")
    message(FATAL_ERROR "${ARGN}: expected exit 2 and '${regex}', no x.csv; got ${rc}: ${err}")
  endif()
  execute_process(COMMAND ${SWEEP} ${common} ${ARGN} RESULT_VARIABLE rc ERROR_VARIABLE err)
  file(READ "${csv}" after)
  if(NOT rc EQUAL 2 OR NOT after STREQUAL before)
    message(FATAL_ERROR "${ARGN}: the existing CSV was touched (${rc}): ${err}")
  endif()
endfunction()
expect_usage_error("theta_w must lie in \\(0, pi\\)" --eps 0.2 --theta_w 4)
expect_usage_error("unknown option '--bogus'" --eps 0.2 --bogus 1)
expect_usage_error("--lam must be > 0, got 0" --eps 0.2 --lam 0)
expect_usage_error("--Omega0 must be a finite number, got 'nan'" --eps 0.2 --Omega0 nan)
expect_usage_error("--eps must be a finite number, got 'abc'" --eps 0.2,abc)
expect_usage_error("--eps must be a finite number, got ''" --eps 0.2,)
expect_usage_error("--grid must be an integer in \\[1, 100000\\], got '0'" --eps 0.2 --grid 0,5)
expect_usage_error("--steps must be an integer in \\[1, 1000000000\\], got '0'" --eps 0.2 --steps 0)
expect_usage_error("--threads must be an integer in \\[0, 4096\\], got '5000'" --eps 0.2 --threads 5000)
expect_usage_error("--K-range must satisfy LO < HI <= 0, got 0,-0.1" --eps 0.2 --K-range 0,-0.1)
expect_usage_error("--K-range LO must be >= -3.14159[0-9]*.*got -4" --eps 0.2 --K-range -4,0)
# A grid too large to hold: refused up front with the bound, never a raw bad_alloc / terminate.
expect_usage_error("--grid 100000,100000 asks for n_phi \\* n_K = 10000000000 orbits.*allowed: n_phi \\* n_K <= [0-9]+"
                   --eps 0.2 --grid 100000,100000)

# An allocation that passes the check but fails anyway (here under a 300 MB address-space limit)
# is reported with the option to reduce. Sanitizer builds reserve more than that at start: skipped.
find_program(SH sh)
if(SH)
  execute_process(COMMAND ${SH} -c "ulimit -v 300000 && exec \"$0\" --eps 0.2 --grid 100000,400 --out \"$1\""
                          ${SWEEP} ${WORK}/oom.csv
                  RESULT_VARIABLE rc ERROR_VARIABLE err)
  if(err MATCHES "Sanitizer|allowed: n_phi")
    message(STATUS "out-of-memory check skipped (sanitizer build or a machine under 1.4 GB): ${err}")
  elseif(NOT rc EQUAL 2 OR NOT err MATCHES "out of memory while allocating the grid of --grid 100000,400.*reduce --grid"
         OR err MATCHES "terminate" OR EXISTS "${WORK}/oom.csv")
    message(FATAL_ERROR "bad_alloc not reported clearly (${rc}): ${err}")
  endif()
endif()
