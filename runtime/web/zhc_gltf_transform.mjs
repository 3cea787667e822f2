// ZHC_light_probes for glTF-Transform (https://gltf-transform.dev, @gltf-transform/core 4.x):
// an Extension class that reads the extension into the Document and writes it back, so scripts
// and the `gltf-transform` CLI (with runtime/web/gltf-transform.config.mjs) keep zhc's probe
// volumes. Spec: docs/gltf-extension.md ("Tool pipelines" says what survives which command).
//
//   import * as core from '@gltf-transform/core';
//   import { defineZhcLightProbes } from '@zhc/runtime/gltf-transform';
//   const ZhcLightProbes = defineZhcLightProbes(core);
//   const io = new core.NodeIO().registerExtensions([...ALL_EXTENSIONS, ZhcLightProbes]);
//
// Why a factory taking the core module instead of `import ... from '@gltf-transform/core'`: core
// recognises extension properties with `instanceof ExtensionProperty` (and its graph with
// `instanceof GraphEdge`), so the class must extend the *same copy* of core that reads and
// writes the Document. The CLI loads its own copy; the config file hands exactly that one in.
//
// How the probe data is held. Each volume is a ZhcLightProbeVolume (an ExtensionProperty, parent
// type Node) holding its JSON definition (everything but buffer indices) and the stored bytes of
// its accessors (ACCESSOR_KEYS: `coefficients`, `positions`, the per-probe `validity`,
// `visibility`, `planes`, `planeSides` and the points' `tetrahedra`, `tetraNeighbours`) and of its
// Draco payload bufferView, exactly as read.
// The bytes are NOT kept as glTF-Transform Accessors: glTF-Transform's meshopt() and the writer's
// EXT_meshopt_compression compress every Accessor of the document (into a uri-less fallback
// buffer that zhc's reader and most loaders cannot read as plain bytes), sparse() turns mostly-zero
// accessors into sparse ones (which zhc refuses), and dedup() merges equal accessors. Holding the
// bytes in the volume makes every transform leave them alone; on writing, each one becomes a new
// tightly packed bufferView (4-byte aligned) of buffer 0 and, for accessors, a new accessor with
// the same componentType, type, count (and name, min, max when the input had them). The bytes
// are bit for bit those read. Node placement is an ordinary ExtensionProperty reference on the
// Node, so it follows the node through flatten, join, instance, prune and dedup (glTF-Transform
// keeps nodes that carry an extension), and a node's world transform is what places the probes.

export const ZHC_LIGHT_PROBES = 'ZHC_light_probes';

// Volume keys whose value is a buffer index: written anew. Every other key of a volume is JSON
// that holds no index and is carried verbatim, except that a key this module does not know is
// only carried when its value is a string or a boolean (a number or an object could be an index
// of something this module cannot renumber, so such a file is refused rather than written wrong).
const KNOWN_KEYS = new Set(['name', 'encoding', 'kind', 'count', 'shAxes', 'layout', 'grid', 'positions', 'coefficients', 'validity', 'visibility',
  'planes', 'planeSides', 'tetrahedra', 'tetraNeighbours', 'quantization', 'luminanceWeights', 'draco', 'extras']);
const ACCESSOR_KEYS = ['positions', 'coefficients', 'validity', 'visibility', 'planes', 'planeSides', 'tetrahedra', 'tetraNeighbours'];

const COMPONENT_BYTES = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };
const TYPE_SIZE = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT2: 4, MAT3: 9, MAT4: 16 };

const clone = (v) => (v === undefined ? undefined : JSON.parse(JSON.stringify(v)));
const pad4 = (n) => (4 - (n % 4)) % 4;

const defined = new WeakMap();

/** Returns the ZHC_light_probes Extension class built on the given @gltf-transform/core module. */
export function defineZhcLightProbes(core) {
  if (!core || typeof core.Extension !== 'function' || typeof core.ExtensionProperty !== 'function')
    throw new Error('defineZhcLightProbes: pass the @gltf-transform/core module namespace');
  if (defined.has(core)) return defined.get(core);
  const { Extension, ExtensionProperty, PropertyType } = core;

  /** One probe volume of ZHC_light_probes: its JSON definition and its stored bytes. */
  class ZhcLightProbeVolume extends ExtensionProperty {
    static EXTENSION_NAME = ZHC_LIGHT_PROBES;

    init() {
      this.extensionName = ZHC_LIGHT_PROBES;
      this.propertyType = 'ZhcLightProbeVolume';
      this.parentTypes = [PropertyType.NODE];
    }

    getDefaults() {
      return Object.assign(super.getDefaults(), { definition: {}, accessors: {}, dracoPayload: null, buffer: null });
    }

    /** The Buffer the probe data is written into (a reference, so prune keeps that buffer). */
    getBuffer() { return this.getRef('buffer'); }
    setBuffer(buffer) { return this.setRef('buffer', buffer); }

    /** The volume's JSON without buffer indices (encoding, count, layout, grid, quantization, ...). */
    getDefinition() { return clone(this.get('definition')); }
    setDefinition(def) { return this.set('definition', clone(def)); }
    getEncoding() { return this.get('definition').encoding; }
    getCount() { return this.get('definition').count; }
    getLayout() { return this.get('definition').layout; }
    getGrid() { return clone(this.get('definition').grid) ?? null; }

    /**
     * The stored data of accessor property `key` ('coefficients', 'positions', 'validity', 'visibility',
     * 'planes', 'planeSides', 'tetrahedra' or 'tetraNeighbours'):
     * { bytes: Uint8Array, componentType, type, count, name?, min?, max? }, or null.
     */
    getAccessorData(key) {
      const a = this.get('accessors')[key];
      return a ? { ...clone({ ...a, bytes: undefined }), bytes: a.bytes.slice() } : null;
    }
    setAccessorData(key, data) {
      if (!ACCESSOR_KEYS.includes(key)) throw new Error(`${ZHC_LIGHT_PROBES}: unknown accessor property '${key}'`);
      const accessors = { ...this.get('accessors') };
      if (data) {
        const elem = (COMPONENT_BYTES[data.componentType] ?? 0) * (TYPE_SIZE[data.type] ?? 0);
        if (!elem || !Number.isInteger(data.count) || data.count < 1 || !(data.bytes instanceof Uint8Array) ||
            data.bytes.byteLength !== data.count * elem)
          throw new Error(`${ZHC_LIGHT_PROBES}: ${key}: bytes do not match componentType/type/count`);
        accessors[key] = { ...clone({ ...data, bytes: undefined }), bytes: data.bytes.slice() };
      } else {
        delete accessors[key];
      }
      return this.set('accessors', accessors);
    }
    /** The Draco point-cloud payload (the bytes of draco.bufferView), or null. */
    getDracoPayload() { const d = this.get('dracoPayload'); return d ? d.slice() : null; }
    setDracoPayload(bytes) { return this.set('dracoPayload', bytes ? bytes.slice() : null); }

    // Property.copy clones plain objects through JSON, which would turn the Uint8Arrays held in
    // 'accessors' into plain objects: copy that attribute by hand.
    copy(other, resolve) {
      super.copy(other, resolve);
      const acc = {};
      for (const [k, a] of Object.entries(other.get('accessors'))) acc[k] = { ...clone({ ...a, bytes: undefined }), bytes: a.bytes.slice() };
      this.set('accessors', acc);
      return this;
    }
  }

  class ZhcLightProbes extends Extension {
    static EXTENSION_NAME = ZHC_LIGHT_PROBES;
    extensionName = ZHC_LIGHT_PROBES;
    prewriteTypes = [PropertyType.BUFFER];

    /** Creates a volume (attach it to a Node with node.setExtension('ZHC_light_probes', v)). */
    createVolume(name = '') { return new ZhcLightProbeVolume(this.document.getGraph(), name); }
    /** The volumes in file order (the order they are written in). */
    listVolumes() { return this.listProperties(); }

    read(context) {
      const json = context.jsonDoc.json;
      const ext = json.extensions?.[ZHC_LIGHT_PROBES];
      if (!ext) return this;
      const fail = (where, what) => { throw new Error(`${ZHC_LIGHT_PROBES}: ${where}: ${what}`); };
      if (!Array.isArray(ext.volumes) || ext.volumes.length === 0) fail('extensions.ZHC_light_probes', 'volumes is not a non-empty array');
      // Other keys of the extension object: extras and index-free unknown keys are carried.
      this._rootDef = {};
      for (const [key, value] of Object.entries(ext)) {
        if (key === 'volumes') continue;
        if (key !== 'extras' && typeof value !== 'string' && typeof value !== 'boolean')
          fail(`extensions.ZHC_light_probes.${key}`, 'unknown property that may reference a buffer; this version cannot renumber it');
        this._rootDef[key] = clone(value);
      }
      const used = new Set();
      const volumes = ext.volumes.map((vdef, vi) => {
        const where = `volumes[${vi}]`;
        if (!vdef || typeof vdef !== 'object' || Array.isArray(vdef)) fail(where, 'not an object');
        const def = {};
        for (const [key, value] of Object.entries(vdef)) {
          if (ACCESSOR_KEYS.includes(key)) continue;
          if (!KNOWN_KEYS.has(key) && typeof value !== 'string' && typeof value !== 'boolean')
            fail(`${where}.${key}`, 'unknown property that may reference a buffer; this version cannot renumber it');
          def[key] = clone(value);
        }
        const volume = this.createVolume(typeof vdef.name === 'string' ? vdef.name : '');
        delete def.name;
        if (vdef.extras !== undefined) { volume.setExtras(clone(vdef.extras)); delete def.extras; }
        let buffer = null;
        for (const key of ACCESSOR_KEYS) {
          if (vdef[key] === undefined) continue;
          const i = vdef[key];
          if (!Number.isInteger(i) || i < 0 || i >= context.accessors.length) fail(`${where}.${key}`, `accessor index ${i} out of range`);
          const adef = json.accessors[i];
          if (adef.sparse) fail(`${where}.${key}`, `accessor ${i} is sparse`);
          const accessor = context.accessors[i];
          const array = accessor.getArray();
          if (!array) fail(`${where}.${key}`, `accessor ${i} has no data`);
          const data = { bytes: new Uint8Array(array.buffer, array.byteOffset, array.byteLength).slice(),
            componentType: adef.componentType, type: adef.type, count: adef.count };
          for (const k of ['name', 'normalized', 'min', 'max']) if (adef[k] !== undefined) data[k] = clone(adef[k]);
          volume.setAccessorData(key, data);
          buffer ??= accessor.getBuffer();
          used.add(accessor);
        }
        if (vdef.draco !== undefined) {
          const b = vdef.draco?.bufferView;
          if (!Number.isInteger(b) || b < 0 || b >= context.bufferViews.length) fail(`${where}.draco.bufferView`, `index ${b} out of range`);
          volume.setDracoPayload(context.bufferViews[b]);
          buffer ??= context.bufferViewBuffers[b];
          delete def.draco.bufferView;
        }
        volume.setDefinition(def);
        volume.setBuffer(buffer ?? this.document.getRoot().listBuffers()[0] ?? this.document.createBuffer());
        return volume;
      });
      // The probe accessors now live in their volumes: drop the Accessors (unless something else
      // of the asset uses the same accessor), so no transform compresses, sparsifies or merges them.
      for (const accessor of used) {
        if (accessor.listParents().every((p) => p.propertyType === PropertyType.ROOT)) accessor.dispose();
      }
      (json.nodes || []).forEach((nodeDef, ni) => {
        const ref = nodeDef.extensions?.[ZHC_LIGHT_PROBES];
        if (!ref) return;
        for (const key of Object.keys(ref))
          if (key !== 'volume') fail(`nodes[${ni}].extensions.ZHC_light_probes.${key}`, 'unknown property; this version cannot carry it');
        if (!Number.isInteger(ref.volume) || ref.volume < 0 || ref.volume >= volumes.length)
          fail(`nodes[${ni}].extensions.ZHC_light_probes.volume`, `index ${ref.volume} out of range`);
        context.nodes[ni].setExtension(ZHC_LIGHT_PROBES, volumes[ref.volume]);
      });
      return this;
    }

    prewrite(context, propertyType) {
      if (propertyType !== PropertyType.BUFFER || this.properties.size === 0) return this;
      // One bufferView per stored array, each padded to 4 bytes so that the next one (and any
      // float accessor) starts 4-byte aligned; write() trims byteLength back to the exact size.
      // The writer lays a buffer out as: accessor data and images (each padded to 4 or 8), then
      // the "other" bufferViews in push order. Other extensions push before this one (prewrite
      // runs in extension-name order, and KHR_draco_mesh_compression pushes already in its
      // Accessor prewrite) and their payloads need not be a multiple of 4 long, so the first array
      // of each buffer gets `lead` zero bytes in front, skipped by its bufferView's byteOffset.
      this._pending = new Map();
      for (const volume of this.listVolumes()) {
        let buffer = volume.getBuffer();
        if (!buffer) volume.setBuffer(buffer = this.document.getRoot().listBuffers()[0] ?? this.document.createBuffer());
        let views = context.otherBufferViews.get(buffer);
        if (!views) context.otherBufferViews.set(buffer, views = []);
        const entry = {};
        for (const key of ACCESSOR_KEYS) {
          const a = volume.get('accessors')[key];
          if (!a) continue;
          entry[key] = this._stage(views, a.bytes);
        }
        const draco = volume.get('dracoPayload');
        if (draco) entry.draco = this._stage(views, draco);
        this._pending.set(volume, entry);
      }
      return this;
    }

    _stage(views, bytes) {
      const lead = pad4(views.reduce((n, v) => n + v.byteLength, 0));
      const padded = new Uint8Array(lead + bytes.byteLength + pad4(lead + bytes.byteLength));
      padded.set(bytes, lead);
      views.push(padded);
      return { padded, lead, byteLength: bytes.byteLength };
    }

    write(context) {
      if (this.properties.size === 0) return this;
      const json = context.jsonDoc.json;
      const view = (staged) => {
        const index = context.otherBufferViewsIndexMap.get(staged.padded);
        const bv = json.bufferViews[index];
        if (index === undefined || !bv) throw new Error(`${ZHC_LIGHT_PROBES}: probe data was not written into a buffer`);
        bv.byteOffset = (bv.byteOffset ?? 0) + staged.lead;
        bv.byteLength = staged.byteLength;
        if (bv.byteOffset % 4 !== 0) throw new Error(`${ZHC_LIGHT_PROBES}: probe bufferView not 4-byte aligned`);
        return index;
      };
      json.accessors = json.accessors || [];
      const volumeIndex = new Map();
      const defs = this.listVolumes().map((volume, vi) => {
        const staged = this._pending?.get(volume) ?? {};
        const def = volume.getDefinition();
        const out = {};
        if (volume.getName()) out.name = volume.getName();
        // Same key order as the definition, buffer indices in their usual places.
        const keys = Object.keys(def);
        for (const key of ACCESSOR_KEYS) if (volume.get('accessors')[key] && !keys.includes(key)) keys.push(key);
        for (const key of keys) {
          if (ACCESSOR_KEYS.includes(key)) {
            const a = volume.get('accessors')[key];
            if (!a) continue;
            const adef = { bufferView: view(staged[key]), componentType: a.componentType, count: a.count, type: a.type };
            for (const k of ['name', 'normalized', 'min', 'max']) if (a[k] !== undefined) adef[k] = clone(a[k]);
            json.accessors.push(adef);
            out[key] = json.accessors.length - 1;
          } else if (key === 'draco') {
            out.draco = { bufferView: staged.draco ? view(staged.draco) : undefined, ...def.draco };
            if (out.draco.bufferView === undefined) throw new Error(`${ZHC_LIGHT_PROBES}: volumes[${vi}]: draco without payload`);
          } else {
            out[key] = def[key];
          }
        }
        const extras = volume.getExtras();
        if (extras && Object.keys(extras).length) out.extras = clone(extras);
        volumeIndex.set(volume, vi);
        return out;
      });
      this._pending = null;
      for (const node of this.document.getRoot().listNodes()) {
        const volume = node.getExtension(ZHC_LIGHT_PROBES);
        if (!volume) continue;
        const nodeDef = json.nodes[context.nodeIndexMap.get(node)];
        nodeDef.extensions = nodeDef.extensions || {};
        nodeDef.extensions[ZHC_LIGHT_PROBES] = { volume: volumeIndex.get(volume) };
      }
      json.extensions = json.extensions || {};
      json.extensions[ZHC_LIGHT_PROBES] = { volumes: defs, ...clone(this._rootDef ?? {}) };
      return this;
    }
  }

  ZhcLightProbes.Volume = ZhcLightProbeVolume;
  defined.set(core, ZhcLightProbes);
  return ZhcLightProbes;
}
