// js.astc_webgl's page: each ASTC texture of /work/spec.json uploaded with WEBGL_compressed_texture_astc
// (compressedTexImage2D of the KTX2 level data), read texel for texel by a texelFetch shader into an
// RGBA32F framebuffer (EXT_color_buffer_float), posted back as float arrays. HDR textures are decoded
// only when the extension lists the "hdr" profile.
const report = { errors: window.zhcErrors, textures: {} };
const done = async () => {
  console.log('zhc astc webgl page done');
  await fetch('/result', { method: 'POST', body: JSON.stringify(report) });
};
try {
  const spec = await (await fetch('/work/spec.json')).json();
  const canvas = document.createElement('canvas');
  const gl = canvas.getContext('webgl2');
  report.webgl2 = !!gl;
  const ext = gl && gl.getExtension('WEBGL_compressed_texture_astc');
  report.astc = !!ext;
  report.profiles = ext ? ext.getSupportedProfiles() : [];
  report.colorBufferFloat = !!(gl && gl.getExtension('EXT_color_buffer_float'));
  report.renderer = gl ? gl.getParameter(gl.RENDERER) : '';
  if (ext && report.colorBufferFloat) {
    const vs = '#version 300 es\nvoid main() { vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2)); gl_Position = vec4(2.0 * p - 1.0, 0.0, 1.0); }';
    const fs = '#version 300 es\nprecision highp float;\nuniform highp sampler2D t;\nout vec4 o;\nvoid main() { o = texelFetch(t, ivec2(gl_FragCoord.xy), 0); }';
    const shader = (type, src) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, src);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const prog = gl.createProgram();
    gl.attachShader(prog, shader(gl.VERTEX_SHADER, vs));
    gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, fs));
    gl.linkProgram(prog);
    if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(prog));
    gl.useProgram(prog);
    gl.bindVertexArray(gl.createVertexArray());
    for (const t of spec.textures) {
      if (t.hdr && !report.profiles.includes('hdr')) continue;
      const data = new Uint8Array(await (await fetch('/work/' + t.file)).arrayBuffer());
      const tex = gl.createTexture();
      gl.activeTexture(gl.TEXTURE0);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.compressedTexImage2D(gl.TEXTURE_2D, 0, t.glFormat, t.width, t.height, 0, data);
      const uploadError = gl.getError();
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
      const target = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, target);
      gl.texStorage2D(gl.TEXTURE_2D, 1, gl.RGBA32F, t.width, t.height);
      const fb = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
      gl.bindTexture(gl.TEXTURE_2D, tex);
      gl.uniform1i(gl.getUniformLocation(prog, 't'), 0);
      gl.viewport(0, 0, t.width, t.height);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      const px = new Float32Array(t.width * t.height * 4);
      gl.readPixels(0, 0, t.width, t.height, gl.RGBA, gl.FLOAT, px);
      report.textures[t.name] = { uploadError, drawError: gl.getError(), texels: Array.from(px) };
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      gl.deleteFramebuffer(fb);
      gl.deleteTexture(target);
      gl.deleteTexture(tex);
    }
  }
} catch (e) {
  window.zhcErrors.push('exception: ' + (e && e.stack || e));
}
document.title = 'zhc ASTC WebGL2 decode test: done';
await done();
