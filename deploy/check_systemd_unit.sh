#!/usr/bin/env bash
# Checks deploy/systemd/cablesim-server.service (CTest systemd_unit_test):
# `systemd-analyze verify` must accept it without a single message (an
# unknown key is only a warning there, with exit 0: any output fails here),
# and `systemd-analyze security --offline` must rate its sandbox at an
# exposure of at most 2.0 of 10 ("OK"). The unit names the installed
# /usr/local/bin/cablesim-server, which verify checks exists: a copy naming
# the build's binary is checked instead.
#
# Usage: check_systemd_unit.sh UNIT_FILE BIN_DIR. Exit 77 (CTest: skipped)
# without systemd-analyze (Debian: the systemd package).
set -euo pipefail
unit=$1
bin_dir=$2
if ! command -v systemd-analyze > /dev/null; then
  echo "SKIPPED: systemd-analyze is not installed (Debian: apt-get install systemd)"
  exit 77
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
copy="$tmp/$(basename "$unit")"
sed "s#/usr/local/bin/cablesim-server#${bin_dir}/cablesim-server#g" "$unit" > "$copy"
grep -q "^ExecStart=${bin_dir}/cablesim-server " "$copy" || {
  echo "FAILED: $unit: no ExecStart=/usr/local/bin/cablesim-server line"
  exit 1
}
set +e
messages=$(cd "$tmp" && systemd-analyze verify "$copy" 2>&1)
rc=$?
set -e
if [ "$rc" -ne 0 ] || [ -n "$messages" ]; then
  echo "FAILED: systemd-analyze verify $unit (exit $rc):"
  echo "$messages"
  exit 1
fi
echo "systemd-analyze verify: no messages"
set +e
security=$(cd "$tmp" && systemd-analyze security --offline=yes --threshold=20 "$copy" 2>&1)
rc=$?
set -e
echo "$security" | grep "Overall exposure level" || true
if [ "$rc" -ne 0 ]; then
  echo "FAILED: the sandbox's exposure is above 2.0 (systemd-analyze security exit $rc):"
  echo "$security" | grep -v "^✓" || true
  exit 1
fi
for key in DynamicUser=yes StateDirectory=cablesim ProtectSystem=strict NoNewPrivileges=yes; do
  grep -qx "$key" "$unit" || { echo "FAILED: $unit lacks $key"; exit 1; }
done
echo "systemd unit: verified"
