#!/usr/bin/env bash
# Installs every package cablesim builds and tests with: Debian 12 packages
# only, nothing downloaded at build time. Runs apt-get as root (directly, or
# through sudo when not root).
set -euo pipefail
packages=(
  cmake g++ make pkg-config
  libeigen3-dev libabsl-dev libspectra-dev
  libprotobuf-dev protobuf-compiler
  libgrpc++-dev protobuf-compiler-grpc
  libgtest-dev libgmock-dev libbenchmark-dev libcli11-dev nlohmann-json3-dev
  libsqlite3-dev zlib1g-dev libzstd-dev libssl-dev
  libpq-dev postgresql
  python3 python3-grpcio python3-protobuf python3-numpy python3-matplotlib python3-pil
  python3-venv python3-setuptools python3-wheel python3-pandas
  clang libclang-rt-14-dev
  openssl iproute2 strace curl systemd python3-yaml
  mkdocs mkdocs-material
)
as_root=()
if [ "$(id -u)" -ne 0 ]; then as_root=(sudo); fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
else
  export DEBIAN_FRONTEND=noninteractive
  "${as_root[@]}" apt-get update -q
  "${as_root[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
fi
# The Node.js example client's npm packages (client/node/package-lock.json),
# only when node is installed: CTest's node_client_test needs them.
node_dir="$(cd "$(dirname "$0")/.." && pwd)/client/node"
if command -v npm > /dev/null && [ ! -d "$node_dir/node_modules/@grpc/grpc-js" ]; then
  (cd "$node_dir" && npm ci --no-audit --no-fund --loglevel=error) ||
    echo "install-deps: npm ci in client/node failed: node_client_test will fail" >&2
fi
# The deployment checks' npm packages (deploy/package-lock.json: the
# Kubernetes schemas of kubernetes-models, a YAML parser): CTest's
# deploy_files_slow_test needs them.
deploy_dir="$(cd "$(dirname "$0")" && pwd)"
if command -v npm > /dev/null && [ ! -d "$deploy_dir/node_modules/kubernetes-models" ]; then
  (cd "$deploy_dir" && npm ci --no-audit --no-fund --loglevel=error) ||
    echo "install-deps: npm ci in deploy failed: deploy_files_slow_test will fail" >&2
fi
