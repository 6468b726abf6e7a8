#!/bin/sh
# hovering_sweep resumes from a CSV that may come from anyone (docs/threat-model.md): a FIFO, a
# file beyond 1 GiB or a line beyond 64 KiB is refused with one clear message and status 2 before
# it is read, promptly and without a large allocation; nothing is computed and the file is kept.
set -eu
SWEEP=$1
WORK=$2
rm -rf "$WORK"
mkdir -p "$WORK"
cat > "$WORK/s.toml" <<'TOML'
kind = "hovering_area"
output = "out/s.png"
n_steps = 200000
samples = 20000
eps = [0.2]
[map]
Omega0 = "OMEGA_G"
theta_w = "3*pi/4"
[[series]]
label = "paper"
TOML

# refused CSV MESSAGE: status 2 within 10 s (a hang guard: computing the point takes minutes), the
# message on stderr, peak memory (GNU time's max RSS, when installed) below 200 MB.
refused() {
  csv=$1
  msg=$2
  rc=0
  if [ -x /usr/bin/time ]; then
    timeout 10 /usr/bin/time -f "%M" -o "$WORK/rss" "$SWEEP" --scene "$WORK/s.toml" --out "$csv" 2> "$WORK/err" || rc=$?
  else
    timeout 10 "$SWEEP" --scene "$WORK/s.toml" --out "$csv" 2> "$WORK/err" || rc=$?
  fi
  if [ "$rc" -ne 2 ] || ! grep -q "$msg" "$WORK/err"; then
    echo "$csv: status $rc (want 2), stderr:"; cat "$WORK/err"; echo "(want: $msg)"; exit 1
  fi
  # GNU time writes "Command exited with non-zero status 2", then the max RSS in kB.
  if [ -s "$WORK/rss" ] && [ "$(tail -n 1 "$WORK/rss")" -gt 204800 ]; then
    echo "$csv: max RSS $(tail -n 1 "$WORK/rss") kB (want < 200 MB)"; exit 1
  fi
  rm -f "$WORK/rss"
}

mkfifo "$WORK/fifo.csv"
refused "$WORK/fifo.csv" "is not a regular file"

# A sparse 2 GiB file: refused by its size, never read.
truncate -s 2G "$WORK/big.csv"
refused "$WORK/big.csv" "has 2147483648 bytes; allowed: at most 1073741824"
[ "$(stat -c %s "$WORK/big.csv")" = 2147483648 ] || { echo "big.csv was changed"; exit 1; }

# A 16 MB line without a newline (the header is expected first): refused after 64 KiB.
head -c 16000000 /dev/zero | tr '\0' 'x' > "$WORK/long.csv"
refused "$WORK/long.csv" "line 1 is longer than 65536 bytes"
[ "$(stat -c %s "$WORK/long.csv")" = 16000000 ] || { echo "long.csv was changed"; exit 1; }
echo "ok"
