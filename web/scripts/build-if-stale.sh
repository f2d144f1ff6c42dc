#!/usr/bin/env bash
# Installs the dashboard's npm packages (npm ci, from the committed lockfile) and builds
# web/dist, each only when its inputs changed since the last run (hash stamps), so ci/up and
# ci/test stay fast. Called by ci/setup.
set -euo pipefail
WEB="$(cd "$(dirname "$0")/.." && pwd)"
ROOT="$(cd "$WEB/.." && pwd)"
cd "$WEB"

command -v npm >/dev/null || { echo "web: npm not found (ci/setup installs nodejs and npm)" >&2; exit 1; }

hash_of() { # files/folders -> one sha256 over their paths and contents
  find "$@" -type f -print0 | sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1
}

deps_hash="$(hash_of package.json package-lock.json)"
if [[ ! -d node_modules || "$(cat node_modules/.gbdcs-stamp 2>/dev/null)" != "$deps_hash" ]]; then
  echo "web: npm ci"
  npm ci --no-audit --no-fund --loglevel=error
  echo "$deps_hash" > node_modules/.gbdcs-stamp
else
  echo "web: npm packages up to date"
fi

build_hash="$(hash_of package.json package-lock.json index.html vite.config.ts tsconfig.json \
  src public scripts "$ROOT/core/contracts/schemas")"
if [[ ! -f dist/index.html || "$(cat dist/.gbdcs-stamp 2>/dev/null)" != "$build_hash" ]]; then
  echo "web: building web/dist"
  npm run --silent build
  echo "$build_hash" > dist/.gbdcs-stamp
else
  echo "web: web/dist up to date"
fi
