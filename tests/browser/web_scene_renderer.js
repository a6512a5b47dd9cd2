// The GL back end (pipeline/render/gl/gl_scene_renderer.cc) in a web browser, on WebGL 2: the
// device's layered scene (POST /api/jobs/ID/preview/scene, pipeline/render/gl/web_scene.h) drawn
// with the back end's own shaders (gl_render_shaders.h, handed in as text, so both run the same
// code): the viewing weights, every view's segments front to back into the three rendering
// buffers, and the soft z resolve. What differs, because WebGL 2 itself has no 16-bit normalised
// targets (EXT_texture_norm16 is an extension Chromium's software WebGL lacks) and a float
// target does not saturate its blend: the rendering buffers are 8-bit, depth split over two
// channels (16 bits where a fragment is opaque, about 8 at a soft edge, where each blend rounds);
// and the holes are left as they are (the back end fills them on the CPU after its read-back). tests/browser/web_scene_bench.py measures it against the device.
(function () {
  'use strict';

  // highp everywhere: a fragment shader's samplers default to lowp, too coarse for view indices,
  // colours on 0..255 and split depth on a GPU that honours it.
  const HEADER = '#version 300 es\nprecision highp float;\nprecision highp int;\nprecision highp sampler2D;\n' +
      'precision highp usampler2D;\n';
  const FLOATS_PER_INSTANCE = 22;  // corners 8, homography 9, plane 3, segment 1, texture weight 1
  const FLOATS_PER_SEGMENT = 8;    // web_scene.h: bbox x, y, width, height, plane a, b, c, index
  const NEAR_DEPTH_M = 1e-3;
  const BOX_GRID = 32;

  // The 8-bit rendering buffers' depth: z / z_scale as a high and a low byte, each blended like
  // colour, so their sum stays linear in the blend weights.
  const DEPTH_OUT = 'depth_out = vec4(z / z_scale, 0.0, 0.0, min(alpha, 1.0));';
  const DEPTH_OUT_SPLIT =
      'float q = clamp(z / z_scale, 0.0, 1.0) * 255.0;\n  depth_out = vec4(floor(q) / 255.0, fract(q), 0.0, min(alpha, 1.0));';
  const DEPTH_IN = 'vec3 zs = vec3(texelFetch(depth_slot0, p, 0).r, texelFetch(depth_slot1, p, 0).r, texelFetch(depth_slot2, p, 0).r);';
  const DEPTH_IN_SPLIT = `vec4 d0 = texelFetch(depth_slot0, p, 0), d1 = texelFetch(depth_slot1, p, 0), d2 = texelFetch(depth_slot2, p, 0);
  vec3 zs = vec3(d0.r + d0.g / 255.0, d1.r + d1.g / 255.0, d2.r + d2.g / 255.0);`;

  // The back end's resolved frame (B, G, R on 0..255, alpha) shown on the canvas: covered pixels
  // (alpha >= 0.5, as the back end counts them) in colour, holes black; rows flipped, since the
  // canvas's first row is at the bottom.
  const DISPLAY_SHADER = `
uniform sampler2D resolved;
out vec4 colour;
void main() {
  ivec2 size = textureSize(resolved, 0);
  vec4 c = texelFetch(resolved, ivec2(gl_FragCoord.x, float(size.y) - gl_FragCoord.y), 0);
  colour = c.a >= 0.5 ? vec4(c.bgr / 255.0, 1.0) : vec4(0.0, 0.0, 0.0, 1.0);
}`;

  function replaceOnce(text, from, to, what) {
    if (text.split(from).length !== 2) throw new Error(`web scene renderer: the ${what} shader changed; cannot adapt it`);
    return text.replace(from, to);
  }

  // 3x3 matrices as row-major arrays of 9; vectors as arrays of 3.
  const mul = (a, b) => {
    const out = new Array(9);
    for (let i = 0; i < 3; ++i) {
      for (let j = 0; j < 3; ++j) out[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    }
    return out;
  };
  const apply = (m, v) => [m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
    m[6] * v[0] + m[7] * v[1] + m[8] * v[2]];
  const transpose = (m) => [m[0], m[3], m[6], m[1], m[4], m[7], m[2], m[5], m[8]];
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
  const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
  const K = (c) => [c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1];
  const KInverse = (c) => [1 / c.fx, 0, -c.cx / c.fx, 0, 1 / c.fy, -c.cy / c.fy, 0, 0, 1];
  // Rigid transforms {r, t}: x -> r x + t.
  const compose = (a, b) => ({r: mul(a.r, b.r), t: apply(a.r, b.t).map((v, i) => v + a.t[i])});
  const inverse = (a) => {
    const rt = transpose(a.r);
    return {r: rt, t: scale(apply(rt, a.t), -1)};
  };
  const centreOf = (pose) => inverse(pose).t;

  // pipeline/render/texture_stretch.cc.
  function textureStretch(h, px, uniform) {
    const q = apply(h, [px[0], px[1], 1]);
    if (!(Math.abs(q[2]) > 1e-12) || !(uniform > 0)) return 1;
    const u = q[0] / q[2], v = q[1] / q[2];
    const j00 = (h[0] - u * h[6]) / q[2], j01 = (h[1] - u * h[7]) / q[2];
    const j10 = (h[3] - v * h[6]) / q[2], j11 = (h[4] - v * h[7]) / q[2];
    const a = j00 * j00 + j10 * j10, b = j00 * j01 + j10 * j11, c = j01 * j01 + j11 * j11;
    const sigma2 = 0.5 * (a + c - Math.sqrt((a - c) * (a - c) + 4 * b * b));
    if (!(sigma2 > 0)) return Infinity;
    return 1 / (Math.sqrt(sigma2) * uniform);
  }
  function textureWeight(stretch, fade) {
    if (fade.fade_from <= 0 || !(stretch > fade.fade_from)) return 1;
    if (!(stretch < fade.fade_to)) return 0;
    return (fade.fade_to - stretch) / (fade.fade_to - fade.fade_from);
  }

  class WebSceneRenderer {
    // gl: a WebGL 2 context; scene: the ArrayBuffer of web_scene.h; shaders: gl_render_shaders.h's
    // texts by name (full_screen_vertex, view_weights, segment_vertex, segment_fragment, soft_z_resolve).
    constructor(gl, scene, shaders) {
      this.gl = gl;
      if (!gl.getExtension('EXT_color_buffer_float')) throw new Error('web scene renderer: no EXT_color_buffer_float (float targets)');
      const prefix = new Uint32Array(scene, 0, 4);
      if (prefix[0] !== 0x53575850 || prefix[1] !== 1) throw new Error('web scene renderer: not a version 1 web scene');
      this.header = JSON.parse(new TextDecoder().decode(new Uint8Array(scene, 16, prefix[2])));
      const h = this.header;
      this.views = h.views.map((v) => ({
        camera: v, pose: {r: v.rotation, t: v.translation},
        segments: new Float64Array(scene, v.segments_offset, v.segments * FLOATS_PER_SEGMENT),
        texels: this.texture(gl.RGBA32UI, v.width, v.height, gl.RGBA_INTEGER, gl.UNSIGNED_INT,
            new Uint32Array(scene, v.texels_offset, v.width * v.height * 4)),
      }));
      const mesh = h.mesh;
      this.mesh = mesh;
      this.meshUniforms = new Float32Array(mesh.uniforms.flat());
      const weights = '#define MESH_VECTORS ' + mesh.uniforms.length + '\n' + shaders.view_weights;
      this.weightsProgram = this.program(shaders.full_screen_vertex, weights);
      this.segmentProgram = this.program(shaders.segment_vertex,
          replaceOnce(shaders.segment_fragment, DEPTH_OUT, DEPTH_OUT_SPLIT, 'segment'));
      this.resolveProgram = this.program(shaders.full_screen_vertex,
          replaceOnce(shaders.soft_z_resolve, DEPTH_IN, DEPTH_IN_SPLIT, 'resolve'));
      this.displayProgram = this.program(shaders.full_screen_vertex, DISPLAY_SHADER);
      this.emptyVao = gl.createVertexArray();
      this.instanceVao = gl.createVertexArray();
      this.instanceBuffer = gl.createBuffer();
      this.targets = null;
      this.stats = {};
    }

    texture(internal, width, height, format, type, data) {
      const gl = this.gl;
      const t = gl.createTexture();
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texStorage2D(gl.TEXTURE_2D, 1, internal, width, height);
      for (const p of [gl.TEXTURE_MIN_FILTER, gl.TEXTURE_MAG_FILTER]) gl.texParameteri(gl.TEXTURE_2D, p, gl.NEAREST);
      if (data) {
        gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
        gl.texSubImage2D(gl.TEXTURE_2D, 0, 0, 0, width, height, format, type, data);
      }
      return t;
    }

    program(vertex, fragment) {
      const gl = this.gl;
      const shader = (type, text) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, HEADER + text);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error('web scene renderer: ' + gl.getShaderInfoLog(s));
        return s;
      };
      const p = gl.createProgram();
      gl.attachShader(p, shader(gl.VERTEX_SHADER, vertex));
      gl.attachShader(p, shader(gl.FRAGMENT_SHADER, fragment));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error('web scene renderer: ' + gl.getProgramInfoLog(p));
      return p;
    }

    framebuffer(textures) {
      const gl = this.gl;
      const fbo = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fbo);
      textures.forEach((t, i) => gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0 + i, gl.TEXTURE_2D, t, 0));
      gl.drawBuffers(textures.map((_, i) => gl.COLOR_ATTACHMENT0 + i));
      if (gl.checkFramebufferStatus(gl.FRAMEBUFFER) !== gl.FRAMEBUFFER_COMPLETE) {
        throw new Error('web scene renderer: a framebuffer is incomplete');
      }
      return fbo;
    }

    targetsFor(width, height) {
      if (this.targets && this.targets.width === width && this.targets.height === height) return this.targets;
      const gl = this.gl;
      if (this.targets) {  // another size: the old ones go
        const old = this.targets;
        [old.slotViews, old.slotWeights, ...old.colour, ...old.depth, old.resolved, old.resolvedDepth].forEach((x) => gl.deleteTexture(x));
        [old.weightsFbo, ...old.slotFbo, old.resolveFbo].forEach((x) => gl.deleteFramebuffer(x));
      }
      const t = {width, height};
      t.slotViews = this.texture(gl.RGBA32F, width, height);
      t.slotWeights = this.texture(gl.RGBA32F, width, height);
      t.weightsFbo = this.framebuffer([t.slotViews, t.slotWeights]);
      t.colour = [0, 1, 2].map(() => this.texture(gl.RGBA8, width, height));
      t.depth = [0, 1, 2].map(() => this.texture(gl.RGBA8, width, height));
      t.slotFbo = [0, 1, 2].map((k) => this.framebuffer([t.colour[k], t.depth[k]]));
      t.resolved = this.texture(gl.RGBA32F, width, height);
      t.resolvedDepth = this.texture(gl.R32F, width, height);
      t.resolveFbo = this.framebuffer([t.resolved, t.resolvedDepth]);
      this.targets = t;
      return t;
    }

    // gl_view_mesh.cc: where a ray meets the mesh plane, and the views with a slot there.
    meshPoint(centre, dir) {
      const m = this.mesh;
      const s = dot(m.normal, dir);
      const h = dot(m.normal, sub(centre, m.origin));
      const x = Math.abs(s) <= 1e-9 * Math.hypot(...dir) ? centre : sub(centre, scale(dir, h / s));
      const d = sub(x, m.origin);
      return [dot(d, m.axis1), dot(d, m.axis2)];
    }
    triangleAt(q) {
      const u = this.mesh.uniforms;
      for (let i = 0; i < this.mesh.triangles; ++i) {
        const a = u[3 * i], b = u[3 * i + 1], c = u[3 * i + 2];
        const v0 = [b[0] - a[0], b[1] - a[1]], v1 = [c[0] - a[0], c[1] - a[1]], v2 = [q[0] - a[0], q[1] - a[1]];
        const den = v0[0] * v1[1] - v1[0] * v0[1];
        if (Math.abs(den) < 1e-20) continue;
        const wb = (v2[0] * v1[1] - v1[0] * v2[1]) / den, wc = (v0[0] * v2[1] - v2[0] * v0[1]) / den;
        if (1 - wb - wc >= -1e-6 && wb >= -1e-6 && wc >= -1e-6) return i;
      }
      return -1;
    }
    slotViewsAt(q) {
      const m = this.mesh, u = m.uniforms;
      if (m.single_view >= 0) return [m.single_view, -1, -1];
      const views = [-1, -1, -1];
      const add = (view) => {
        for (let k = 0; k < 3; ++k) {
          if (views[k] === view) return;
          if (views[k] < 0) { views[k] = view; return; }
        }
      };
      const t = this.triangleAt(q);
      if (t >= 0) {
        for (let k = 0; k < 3; ++k) add(u[3 * t + k][2]);
        return views;
      }
      let best = Infinity, bestEdge = null;
      for (let e = 0; e < m.edges; ++e) {
        const a = u[3 * m.triangles + 2 * e], b = u[3 * m.triangles + 2 * e + 1];
        const ab = [b[0] - a[0], b[1] - a[1]];
        const s = Math.min(1, Math.max(0, ((q[0] - a[0]) * ab[0] + (q[1] - a[1]) * ab[1]) /
            Math.max(ab[0] * ab[0] + ab[1] * ab[1], 1e-30)));
        const dist = Math.hypot(q[0] - a[0] - s * ab[0], q[1] - a[1] - s * ab[1]);
        if (dist < best) { best = dist; bestEdge = [a, b]; }
      }
      if (bestEdge) { add(bestEdge[0][2]); add(bestEdge[1][2]); }
      return views;
    }
    // GlSceneRenderer::ViewBoxes: per view and slot, the box of output pixels it may hold it in.
    viewBoxes(camera, dirFromPixel, centre) {
      const boxes = this.views.map(() => [null, null, null]);
      const cellX = camera.width / BOX_GRID, cellY = camera.height / BOX_GRID;
      for (let gy = 0; gy <= BOX_GRID; ++gy) {
        for (let gx = 0; gx <= BOX_GRID; ++gx) {
          const px = [Math.min(gx * cellX, camera.width - 1), Math.min(gy * cellY, camera.height - 1), 1];
          const slots = this.slotViewsAt(this.meshPoint(centre, apply(dirFromPixel, px)));
          for (let k = 0; k < 3; ++k) {
            if (slots[k] < 0) continue;
            const x0 = Math.max(0, Math.floor(px[0] - cellX - 1)), y0 = Math.max(0, Math.floor(px[1] - cellY - 1));
            const x1 = Math.min(camera.width, Math.floor(px[0] - cellX - 1) + Math.ceil(2 * cellX + 3));
            const y1 = Math.min(camera.height, Math.floor(px[1] - cellY - 1) + Math.ceil(2 * cellY + 3));
            const box = boxes[slots[k]][k];
            boxes[slots[k]][k] = box ? [Math.min(box[0], x0), Math.min(box[1], y0), Math.max(box[2], x1), Math.max(box[3], y1)]
                                     : [x0, y0, x1, y1];
          }
        }
      }
      return boxes;
    }

    // The per-instance data of every view's segments, front to back (GlSceneRenderer::RenderRaw).
    instances(camera, novel, boxes) {
      const kNovel = K(camera), kNovelInverse = KInverse(camera);
      const fade = this.header.texture_stretch;
      let zMax = 0;
      const perView = this.views.map((view, v) => {
        if (boxes[v].every((b) => !b)) return [];
        const kSource = K(view.camera), kSourceInverse = KInverse(view.camera);
        const sourceFromNovel = compose(view.pose, inverse(novel));
        const novelFromSource = inverse(sourceFromNovel);
        const rRel = sourceFromNovel.r, tRel = sourceFromNovel.t;
        const sorted = [];
        const segs = view.segments;
        for (let i = 0; i < view.camera.segments; ++i) {
          const o = i * FLOATS_PER_SEGMENT;
          const [bx, by, bw, bh, a, b, c, index] = segs.subarray(o, o + FLOATS_PER_SEGMENT);
          const planeSource = apply(transpose(kSource), [a, b, c]);
          const denominator = 1 - dot(planeSource, tRel);
          if (!(denominator > 1e-12)) continue;
          const planeNovel = scale(apply(transpose(rRel), planeSource), 1 / denominator);
          const invDepthNovel = apply(transpose(kNovelInverse), planeNovel);
          const rPlusTn = rRel.map((value, k) => value + tRel[Math.floor(k / 3)] * planeNovel[k % 3]);
          const h = mul(mul(kSource, rPlusTn), kNovelInverse);
          const x0 = bx - 1, x1 = bx + bw, y0 = by - 1, y1 = by + bh;
          const data = new Float32Array(FLOATS_PER_INSTANCE);
          let behind = false;
          [[x0, y0], [x1, y0], [x1, y1], [x0, y1]].forEach(([x, y], k) => {
            if (behind) return;
            const zSource = 1 / (a * x + b * y + c);
            const p = apply(novelFromSource.r, scale(apply(kSourceInverse, [x, y, 1]), zSource)).map((value, j) => value + novelFromSource.t[j]);
            if (p[2] <= NEAR_DEPTH_M) { behind = true; return; }
            zMax = Math.max(zMax, p[2]);
            const projected = apply(kNovel, p);
            data[2 * k] = projected[0] / projected[2];
            data[2 * k + 1] = projected[1] / projected[2];
          });
          if (behind) continue;
          data.set(h, 8);
          data.set(invDepthNovel, 17);
          data[20] = index;
          const cx = bx + (bw - 1) / 2, cy = by + (bh - 1) / 2;
          const zCentre = 1 / (a * cx + b * cy + c);
          const centreNovel = apply(novelFromSource.r, scale(apply(kSourceInverse, [cx, cy, 1]), zCentre)).map((value, j) => value + novelFromSource.t[j]);
          let weight = 1;
          if (fade.fade_from > 0) {
            const centrePx = apply(kNovel, centreNovel);
            weight = textureWeight(textureStretch(h, [centrePx[0] / centrePx[2], centrePx[1] / centrePx[2]],
                kNovel[0] / kSource[0] * zCentre / centreNovel[2]), fade);
            if (weight <= 0) continue;
          }
          data[21] = weight;
          sorted.push({depth: Math.fround(centreNovel[2]), index, data});
        }
        sorted.sort((p, q) => (p.depth !== q.depth ? p.depth - q.depth : p.index - q.index));
        return sorted;
      });
      return {perView, zScale: Math.max(zMax, NEAR_DEPTH_M) * 1.0001};
    }

    // Draws the frame of camera {width, height, fx, fy, cx, cy, rotation (cam_from_world,
    // row-major), translation} into the resolve target, and shows it on the canvas.
    render(camera) {
      const gl = this.gl;
      const started = performance.now();
      const t = this.targetsFor(camera.width, camera.height);
      const novel = {r: camera.rotation, t: camera.translation};
      const centre = centreOf(novel);
      const dirFromPixel = mul(transpose(novel.r), KInverse(camera));
      const boxes = this.viewBoxes(camera, dirFromPixel, centre);
      const {perView, zScale} = this.instances(camera, novel, boxes);
      this.stats.setup_ms = performance.now() - started;

      // Pass 1: the viewing weights.
      gl.disable(gl.BLEND);
      gl.disable(gl.SCISSOR_TEST);
      gl.viewport(0, 0, camera.width, camera.height);
      gl.bindFramebuffer(gl.FRAMEBUFFER, t.weightsFbo);
      let p = this.weightsProgram;
      gl.useProgram(p);
      const at = (name) => gl.getUniformLocation(p, name);
      gl.uniformMatrix3fv(at('dir_from_pixel'), false, transpose(dirFromPixel));  // column-major
      gl.uniform3fv(at('centre'), centre);
      gl.uniform3fv(at('mesh_origin'), this.mesh.origin);
      gl.uniform3fv(at('mesh_normal'), this.mesh.normal);
      gl.uniform3fv(at('mesh_axis1'), this.mesh.axis1);
      gl.uniform3fv(at('mesh_axis2'), this.mesh.axis2);
      gl.uniform4fv(at('mesh'), this.meshUniforms);
      gl.uniform1i(at('num_triangles'), this.mesh.triangles);
      gl.uniform1i(at('num_edges'), this.mesh.edges);
      gl.uniform1i(at('single_view'), this.mesh.single_view);
      gl.uniform1f(at('weight_exponent'), this.header.viewing_weight_exponent);
      gl.uniform1i(at('hint_triangle'), this.mesh.single_view >= 0 ? -1
          : this.triangleAt(this.meshPoint(centre, apply(dirFromPixel, [camera.width / 2, camera.height / 2, 1]))));
      gl.bindVertexArray(this.emptyVao);
      gl.drawArrays(gl.TRIANGLES, 0, 3);

      // Pass 2: every view's segments into the three rendering buffers, slot by slot.
      const all = new Float32Array(perView.reduce((n, list) => n + list.length, 0) * FLOATS_PER_INSTANCE);
      const first = [];
      let n = 0;
      perView.forEach((list) => {
        first.push(n);
        for (const item of list) all.set(item.data, (n++) * FLOATS_PER_INSTANCE);
      });
      this.stats.instances = n;
      gl.enable(gl.BLEND);
      gl.blendEquation(gl.FUNC_ADD);
      gl.blendFuncSeparate(gl.SRC_ALPHA_SATURATE, gl.ONE, gl.ONE, gl.ONE);
      p = this.segmentProgram;
      gl.useProgram(p);
      gl.uniform2f(gl.getUniformLocation(p, 'viewport_size'), camera.width, camera.height);
      gl.uniform1f(gl.getUniformLocation(p, 'z_scale'), zScale);
      gl.activeTexture(gl.TEXTURE3);
      gl.bindTexture(gl.TEXTURE_2D, t.slotViews);
      gl.uniform1i(gl.getUniformLocation(p, 'slot_views'), 3);
      gl.uniform1i(gl.getUniformLocation(p, 'texels'), 0);
      gl.bindVertexArray(this.instanceVao);
      gl.bindBuffer(gl.ARRAY_BUFFER, this.instanceBuffer);
      gl.bufferData(gl.ARRAY_BUFFER, all, gl.STREAM_DRAW);
      const layout = [[4, 0], [4, 4], [3, 8], [3, 11], [3, 14], [3, 17], [2, 20]];
      for (let k = 0; k < 3; ++k) {
        gl.bindFramebuffer(gl.FRAMEBUFFER, t.slotFbo[k]);
        gl.disable(gl.SCISSOR_TEST);
        gl.clearBufferfv(gl.COLOR, 0, [0, 0, 0, 0]);
        gl.clearBufferfv(gl.COLOR, 1, [0, 0, 0, 0]);
        gl.enable(gl.SCISSOR_TEST);
        gl.uniform1i(gl.getUniformLocation(p, 'slot'), k);
        this.views.forEach((view, v) => {
          const box = boxes[v][k];
          if (!box || perView[v].length === 0) return;
          gl.scissor(box[0], box[1], box[2] - box[0], box[3] - box[1]);
          gl.activeTexture(gl.TEXTURE0);
          gl.bindTexture(gl.TEXTURE_2D, view.texels);
          gl.uniform1f(gl.getUniformLocation(p, 'view_index'), v);
          layout.forEach(([size, offset], a) => {
            gl.enableVertexAttribArray(a);
            gl.vertexAttribPointer(a, size, gl.FLOAT, false, FLOATS_PER_INSTANCE * 4, (first[v] * FLOATS_PER_INSTANCE + offset) * 4);
            gl.vertexAttribDivisor(a, 1);
          });
          gl.drawArraysInstanced(gl.TRIANGLE_STRIP, 0, 4, perView[v].length);
        });
      }
      gl.disable(gl.SCISSOR_TEST);
      gl.disable(gl.BLEND);

      // Pass 3: the soft z resolve.
      gl.bindFramebuffer(gl.FRAMEBUFFER, t.resolveFbo);
      p = this.resolveProgram;
      gl.useProgram(p);
      const bind = (name, unit, texture) => {
        gl.activeTexture(gl.TEXTURE0 + unit);
        gl.bindTexture(gl.TEXTURE_2D, texture);
        gl.uniform1i(gl.getUniformLocation(p, name), unit);
      };
      for (let k = 0; k < 3; ++k) {
        bind('colour_slot' + k, k, t.colour[k]);
        bind('depth_slot' + k, 3 + k, t.depth[k]);
      }
      bind('slot_weights', 6, t.slotWeights);
      gl.uniform1f(gl.getUniformLocation(p, 'z_scale'), zScale);
      gl.uniform1f(gl.getUniformLocation(p, 'rho'), this.header.rho_m);
      gl.uniform1f(gl.getUniformLocation(p, 'gamma'), this.header.gamma_m);
      gl.bindVertexArray(this.emptyVao);
      gl.drawArrays(gl.TRIANGLES, 0, 3);

      // On the canvas (its size the frame's).
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      if (gl.canvas.width !== camera.width || gl.canvas.height !== camera.height) {
        gl.canvas.width = camera.width;
        gl.canvas.height = camera.height;
      }
      gl.viewport(0, 0, camera.width, camera.height);
      p = this.displayProgram;
      gl.useProgram(p);
      bind('resolved', 0, t.resolved);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      // Waits for the GPU (a pixel read back), so the time counts the drawing, not only its queueing.
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
      this.stats.frame_ms = performance.now() - started;
    }

    // The last frame's resolved colour as (B, G, R on 0..255, alpha) floats, rows in image order.
    resolvedPixels() {
      const gl = this.gl, t = this.targets;
      gl.bindFramebuffer(gl.FRAMEBUFFER, t.resolveFbo);
      gl.readBuffer(gl.COLOR_ATTACHMENT0);
      const out = new Float32Array(t.width * t.height * 4);
      gl.readPixels(0, 0, t.width, t.height, gl.RGBA, gl.FLOAT, out);
      gl.bindFramebuffer(gl.FRAMEBUFFER, null);
      return out;
    }
  }

  window.WebSceneRenderer = WebSceneRenderer;
})();
