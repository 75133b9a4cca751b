#!/bin/sh
# Makes what cablesim-server needs beyond loopback, with the openssl command
# line: a private CA (ca.crt, ca.key), a server certificate it signed
# (tls.crt, tls.key; valid for localhost, 127.0.0.1 and each NAME given) and
# a token file (tokens: "TOKEN TENANT" per line, one token of 32 random
# bytes for the tenant "default"). The same names as a cert-manager
# Certificate's Secret (tls.crt, tls.key, ca.crt), so the server's flags
# read the same paths everywhere (deploy/README.md).
#
# Usage: make-secrets.sh DIR [NAME...]. Does nothing when DIR/tls.crt
# exists (compose.yaml runs it on every start; the first one makes them).
# With CABLESIM_SECRETS_OWNER=UID:GID the files are given to that user
# (the server's; 10001 in the image).
set -eu
dir=$1
shift
if [ -s "$dir/tls.crt" ] && [ -s "$dir/tokens" ]; then
  echo "make-secrets: $dir already holds tls.crt and tokens"
  exit 0
fi
mkdir -p "$dir"
umask 077
san="DNS:localhost,IP:127.0.0.1"
for name in "$@"; do san="$san,DNS:$name"; done
openssl req -x509 -newkey rsa:2048 -nodes -days 3650 -subj "/CN=cablesim CA" \
  -keyout "$dir/ca.key" -out "$dir/ca.crt" 2>/dev/null
openssl req -newkey rsa:2048 -nodes -subj "/CN=cablesim-server" \
  -keyout "$dir/tls.key" -out "$dir/tls.csr" 2>/dev/null
printf 'subjectAltName=%s\nbasicConstraints=CA:FALSE\nextendedKeyUsage=serverAuth\n' "$san" > "$dir/tls.ext"
openssl x509 -req -in "$dir/tls.csr" -CA "$dir/ca.crt" -CAkey "$dir/ca.key" -CAcreateserial \
  -days 825 -extfile "$dir/tls.ext" -out "$dir/tls.crt" 2>/dev/null
rm -f "$dir/tls.csr" "$dir/tls.ext" "$dir/ca.srl"
printf '# TOKEN TENANT (cablesim-server --token-file; clients send the first token)\n%s default\n' \
  "$(openssl rand -hex 32)" > "$dir/tokens"
chmod 0644 "$dir/ca.crt" "$dir/tls.crt"
chmod 0600 "$dir/ca.key" "$dir/tls.key" "$dir/tokens"
if [ -n "${CABLESIM_SECRETS_OWNER:-}" ]; then
  chown "$CABLESIM_SECRETS_OWNER" "$dir/tls.key" "$dir/tokens" "$dir/tls.crt" "$dir/ca.crt"
fi
echo "make-secrets: wrote ca.crt, tls.crt, tls.key and tokens to $dir (names: $san)"
