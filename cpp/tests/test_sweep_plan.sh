#!/bin/sh
# hovering_sweep end to end on plans written by Python (cpp/tests/data/*.plan.toml, from
# `python -m hovering plan ... --quick`): a run writes every point, a rerun resumes without
# computing, Ctrl-C (SIGINT) stops promptly with exit 130 and keeps the finished points, two runs
# on one file never write a point twice, and bad plans or options exit 2 with one line.
#
#   sh test_sweep_plan.sh HOVERING_SWEEP DATA_DIR WORK_DIR
set -u
EXE=$1
DATA=$2
WORK=$3
rm -rf "$WORK"
mkdir -p "$WORK"
cd "$WORK" || exit 1
fail() { echo "FAIL: $*"; exit 1; }
points() { grep -c '^{"key":' "$1"; }

# A plan written by Python runs; its default checkpoint is relative to the plan's folder.
cp "$DATA/sweep_small.plan.toml" "$DATA/flow_small.plan.toml" .
mkdir out
"$EXE" --plan sweep_small.plan.toml --threads 2 2> run1.err || fail "sweep_small: exit $? $(cat run1.err)"
[ "$(points out/sweep_small.sweep.jsonl)" = 4 ] || fail "4 points expected in $(cat out/sweep_small.sweep.jsonl)"
head -n 1 out/sweep_small.sweep.jsonl | grep -qx '{"format":"hovering-checkpoint","version":1}' || fail "no header"
grep -q '^{"provenance":{.*"program":"hovering_sweep"' out/sweep_small.sweep.jsonl || fail "no provenance line"
"$EXE" --plan flow_small.plan.toml --out flow.jsonl 2> flow.err || fail "flow_small: exit $? $(cat flow.err)"
[ "$(points flow.jsonl)" = 1 ] || fail "1 flow point expected"
grep -q '"models":{"measured":{"K_low":' flow.jsonl || fail "the flow point's models are missing: $(cat flow.jsonl)"

# A rerun resumes: nothing computed, nothing written.
cp out/sweep_small.sweep.jsonl before.jsonl
"$EXE" --plan sweep_small.plan.toml 2> run2.err || fail "rerun: exit $?"
grep -q "4 points, 4 already in" run2.err || fail "rerun did not resume: $(cat run2.err)"
cmp -s before.jsonl out/sweep_small.sweep.jsonl || fail "a rerun changed the checkpoint"

# A torn last line (a run killed mid-write) is cut off and its point recomputed.
head -n 4 before.jsonl > torn.jsonl
sed -n 5p before.jsonl | head -c 40 >> torn.jsonl
"$EXE" --plan sweep_small.plan.toml --out torn.jsonl 2> torn.err || fail "torn: exit $? $(cat torn.err)"
grep -q "dropped a last line of 40 bytes without its newline" torn.err || fail "torn line not reported: $(cat torn.err)"
[ "$(points torn.jsonl)" = 4 ] || fail "the torn point was not recomputed"

# Ctrl-C: a hand-written plan whose second point runs for minutes. Interrupted once the first
# point is on disk; exit 130 within a generous bound (a loaded 2-core machine), the point kept.
cat > slow.plan.toml <<'PLAN'
format = "hovering-sweep-plan"
version = 1
kind = "hovering_area"
[[points]]
n_steps = 400
samples = 400
seed = 0
K_low = -0.3
map = { eps = 0.1, Omega0 = 3.883222077450933, theta_w = 2.356194490192345, tau0 = 1.0, tau1 = 0.5, lam = 0.5 }
[[points]]
n_steps = 200000000
samples = 200000
seed = 0
K_low = -0.3
map = { eps = 0.1, Omega0 = 3.883222077450933, theta_w = 2.356194490192345, tau0 = 1.0, tau1 = 0.5, lam = 0.5 }
PLAN
"$EXE" --plan slow.plan.toml --out slow.jsonl 2> slow.err &
PID=$!
i=0
while [ "$(grep -c '^{"key":' slow.jsonl 2>/dev/null || echo 0)" = 0 ]; do
  i=$((i + 1)); [ $i -gt 1200 ] && { kill -9 $PID; fail "the first point took over 120 s"; }
  sleep 0.1
done
sleep 0.5
kill -INT $PID
i=0
while kill -0 $PID 2>/dev/null; do
  i=$((i + 1)); [ $i -gt 600 ] && { kill -9 $PID; fail "no exit 60 s after SIGINT"; }
  sleep 0.1
done
wait $PID
RC=$?
[ $RC = 130 ] || fail "exit $RC after SIGINT, expected 130: $(cat slow.err)"
grep -q "interrupted during \[2/2\]" slow.err || fail "no interruption message: $(cat slow.err)"
[ "$(points slow.jsonl)" = 1 ] || fail "the finished point was not kept"

# Two runs started together on one file: every point once, both succeed.
for trial in 1 2 3 4 5; do
  rm -f two.jsonl
  "$EXE" --plan sweep_small.plan.toml --out two.jsonl --threads 1 2> a.err &
  A=$!
  "$EXE" --plan sweep_small.plan.toml --out two.jsonl --threads 1 2> b.err &
  B=$!
  wait $A || fail "first concurrent run: $(cat a.err)"
  wait $B || fail "second concurrent run: $(cat b.err)"
  [ "$(points two.jsonl)" = 4 ] || fail "trial $trial: $(points two.jsonl) point lines, expected 4: $(cat two.jsonl)"
  [ "$(grep -c '^{"format"' two.jsonl)" = 1 ] || fail "trial $trial: the header twice"
done

# Bad input: exit 2 and one line on stderr, before any file is touched.
expect_bad() {  # expect_bad NEEDLE ARGS...
  needle=$1; shift
  "$EXE" "$@" > bad.out 2> bad.err
  rc=$?
  [ $rc = 2 ] || fail "exit $rc for $*, expected 2: $(cat bad.err)"
  [ "$(wc -l < bad.err)" = 1 ] || fail "more than one line for $*: $(cat bad.err)"
  grep -qF -- "$needle" bad.err || fail "'$needle' not in: $(cat bad.err)"
}
expect_bad "--scene is gone" --scene x.toml
expect_bad "python -m hovering plan x.toml --quick -o PLAN.toml" --scene x.toml --quick
expect_bad "--plan PLAN.toml is required"
sed 's/^version = 1/version = 2/' sweep_small.plan.toml > v2.plan.toml
expect_bad "v2.plan.toml: version = 2: this hovering_sweep reads plan version 1" --plan v2.plan.toml --out v2.jsonl
[ -e v2.jsonl ] && fail "a bad plan created its output"
sed '0,/^n_steps = 400/s//n_steps = 3/' sweep_small.plan.toml > n3.plan.toml
expect_bad "points[0].n_steps = 3: allowed: an integer in [4," --plan n3.plan.toml --out n3.jsonl
expect_bad "is not a regular file" --plan .
printf 'area,error\n1,2\n' > foreign.csv
expect_bad "foreign.csv line 1: the first line is not the header" --plan sweep_small.plan.toml --out foreign.csv
[ "$(cat foreign.csv)" = "$(printf 'area,error\n1,2')" ] || fail "the foreign file was touched"
# Crafted checkpoint lines: exit 2 and one line naming the file, the line and the field, the file
# untouched; never a crash (a key nested a million deep overflowed the stack: SIGSEGV).
head -n 1 before.jsonl > deep.jsonl
{
  printf '{"key":{"a":'
  head -c 1000000 /dev/zero | tr '\0' '['
  head -c 1000000 /dev/zero | tr '\0' ']'
  printf '},"row":{}}\n'
} >> deep.jsonl
cp deep.jsonl deep.before
expect_bad "deep.jsonl line 2: not a line of JSON: nested deeper than 100 levels, in key.a[0][0]" --plan sweep_small.plan.toml --out deep.jsonl
cmp -s deep.jsonl deep.before || fail "the crafted checkpoint was touched"
head -n 1 before.jsonl > twice.jsonl
printf '{"key":{"n":1,"n":2},"row":{"area":1e999}}\n' >> twice.jsonl
expect_bad "twice.jsonl line 2: key.n: the name 'n' twice in one object" --plan sweep_small.plan.toml --out twice.jsonl
# One line without its newline that is no piece of the header: another program's file, kept
# (before: cut to nothing as a torn line, then written over).
printf 'my notes, one line' > notes.txt
expect_bad "notes.txt line 1: the first line is not the header" --plan sweep_small.plan.toml --out notes.txt
[ "$(cat notes.txt)" = "my notes, one line" ] || fail "the one-line file was touched"
# A plan from elsewhere cannot drive the terminal: a label's control characters (an ESC sequence)
# are printed as '?' (before: written to stderr as they were).
sed '0,/^label = .*/s//label = "\\u001b[31mred\\u0007"/' sweep_small.plan.toml > esc.plan.toml
"$EXE" --plan esc.plan.toml --out esc.jsonl --threads 1 2> esc.err || fail "esc: exit $? $(cat esc.err)"
grep -q '\[1/4\] ?\[31mred?, eps' esc.err || fail "the label was not printed as '?[31mred?': $(cat -v esc.err)"
if grep -q "$(printf '\033')" esc.err; then fail "an ESC reached stderr: $(cat -v esc.err)"; fi
# Samples beyond half of this machine's memory: refused before the checkpoint is created (before:
# std::bad_alloc once the run had started).
sed '0,/^samples = 800/s//samples = 9007199254740992/' sweep_small.plan.toml > huge.plan.toml
expect_bad "huge.plan.toml: points[0].samples = 9007199254740992 needs" --plan huge.plan.toml --out huge.jsonl
[ -e huge.jsonl ] && fail "a plan beyond the memory budget created its output"
echo "all hovering_sweep plan checks passed"
