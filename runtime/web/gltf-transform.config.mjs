// glTF-Transform CLI configuration that keeps zhc's ZHC_light_probes volumes:
//
//   gltf-transform optimize in.glb out.glb --config runtime/web/gltf-transform.config.mjs
//
// (--config after the command: the 4.x CLI reads `gltf-transform --config PATH optimize ...` as
// an unknown command "--config".)
// The CLI (@gltf-transform/cli 4.x) imports this module and merges its default export into its
// own configuration with Object.assign, so `extensions` *replaces* the CLI's list: it is
// glTF-Transform's ALL_EXTENSIONS plus ZhcLightProbes (runtime/web/zhc_gltf_transform.mjs).
// `dependencies` (the Draco and meshopt codecs) is left to the CLI's defaults.
//
// @gltf-transform/core and @gltf-transform/extensions are loaded from the place the running
// program (normally the CLI, process.argv[1]) resolves them: the extension class must extend the
// CLI's own copy of core (see zhc_gltf_transform.mjs), and this file may live where no
// node_modules is in reach (runtime/web in a zhc checkout, used with a global or a project-local
// CLI). When the program's folder resolves neither, the bare specifiers are imported from here.
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';
import { defineZhcLightProbes } from './zhc_gltf_transform.mjs';

// The file Node's ESM resolution picks for package `name` ('import' / 'node' / 'default'
// conditions of package.json "exports", else "module" / "main"), searched from file `from`.
function resolvePackageEntry(name, from) {
  const paths = createRequire(from).resolve.paths(name) ?? [];
  for (const dir of paths) {
    const pkgDir = path.join(dir, ...name.split('/'));
    const pkgFile = path.join(pkgDir, 'package.json');
    if (!fs.existsSync(pkgFile)) continue;
    const pkg = JSON.parse(fs.readFileSync(pkgFile, 'utf8'));
    const pick = (e) => {
      if (typeof e === 'string') return e;
      if (!e || typeof e !== 'object') return null;
      if (Object.keys(e).some((k) => k.startsWith('.'))) return pick(e['.']);
      for (const [cond, value] of Object.entries(e)) {
        if (cond === 'import' || cond === 'node' || cond === 'default') {
          const r = pick(value);
          if (r) return r;
        }
      }
      return null;
    };
    const entry = pick(pkg.exports) ?? pkg.module ?? pkg.main ?? 'index.js';
    return path.join(pkgDir, entry);
  }
  return null;
}

async function importLikeProgram(name) {
  let program = process.argv[1];
  try {
    program = program && fs.realpathSync(program);
  } catch {
    program = null;
  }
  const entry = program ? resolvePackageEntry(name, program) : null;
  return entry ? import(pathToFileURL(entry).href) : import(name);
}

const core = await importLikeProgram('@gltf-transform/core');
const { ALL_EXTENSIONS } = await importLikeProgram('@gltf-transform/extensions');
export const ZhcLightProbes = defineZhcLightProbes(core);

export default {
  extensions: [...ALL_EXTENSIONS, ZhcLightProbes],
};
