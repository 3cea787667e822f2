// Node module-resolution hook for the tests: runtime/web imports the bare specifier 'three' (as
// every three.js addon does; browsers map it with an import map, bundlers resolve it), but
// runtime/web has no node_modules of its own. This hook resolves 'three' and 'three/...' from
// tests/js/node_modules (installed by the CTest fixture js.npm_install). Used via
//   import { register } from 'node:module'; register('./three_resolver.mjs', import.meta.url);
const base = new URL('./node_modules/', import.meta.url);
export async function resolve(specifier, context, next) {
  if (specifier === 'three' || specifier.startsWith('three/'))
    return next(specifier, { ...context, parentURL: new URL('../package.json', base).href });
  return next(specifier, context);
}
