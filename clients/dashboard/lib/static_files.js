// Static files for the page: public/ (the page itself) and three.js straight
// from node_modules (no bundler, no CDN: the page's import map points
// "three" at /vendor/three/build/three.module.js), so it works offline.
//
// Contract: resolveStatic(pathname) -> absolute file path or null (not ours,
// or an attempt to leave the allowed folders); contentType(path).
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
export const PUBLIC_DIR = path.resolve(here, '../public');
export const THREE_DIR = path.resolve(here, '../node_modules/three');

// Only these parts of the three package are served.
const THREE_ALLOWED = [path.join(THREE_DIR, 'build'), path.join(THREE_DIR, 'examples', 'jsm')];

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.ico': 'image/x-icon',
};

export function contentType(file) {
  return TYPES[path.extname(file)] ?? 'application/octet-stream';
}

function inside(dir, file) {
  const rel = path.relative(dir, file);
  return rel !== '' && !rel.startsWith('..') && !path.isAbsolute(rel);
}

export function resolveStatic(pathname) {
  let decoded;
  try {
    decoded = decodeURIComponent(pathname);
  } catch {
    return null;
  }
  if (decoded.includes('\0')) return null;
  let file = null;
  if (decoded === '/' || decoded === '/index.html') {
    file = path.join(PUBLIC_DIR, 'index.html');
  } else if (decoded.startsWith('/app/')) {
    file = path.resolve(PUBLIC_DIR, '.' + decoded.slice('/app'.length));
    if (!inside(PUBLIC_DIR, file)) return null;
  } else if (decoded.startsWith('/vendor/three/')) {
    file = path.resolve(THREE_DIR, '.' + decoded.slice('/vendor/three'.length));
    if (!THREE_ALLOWED.some((dir) => inside(dir, file))) return null;
  } else {
    return null;
  }
  try {
    return fs.statSync(file).isFile() ? file : null;
  } catch {
    return null;
  }
}
