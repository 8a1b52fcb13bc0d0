// Where the page's data comes from: the server's /api/ (bvc3d view), or, in a page exported with
// `bvc3d view --export`, script files that hand over the same replies (a page opened from disk may
// not fetch). Replies are JSON or blobs (app/view/blob.hpp): a JSON header and typed arrays.

const exported = typeof window !== 'undefined' && window.BVC3D_EXPORT ? window.BVC3D_EXPORT : null;

export const isExport = () => exported !== null;

// The key of a request: the endpoint and its parameters in name order (app/view/export.cpp).
export function requestKey(endpoint, params = {}) {
  const names = Object.keys(params).sort();
  return names.length ? `${endpoint}?${names.map((k) => `${k}=${params[k]}`).join('&')}` : endpoint;
}

export class RequestError extends Error {
  constructor(status, message) {
    super(message);
    this.status = status;
  }
}

const typed = { f32: Float32Array, f64: Float64Array, i32: Int32Array, u8: Uint8Array };

export function decodeBlob(buffer) {
  const bytes = new Uint8Array(buffer);
  const magic = String.fromCharCode(...bytes.subarray(0, 4));
  if (magic !== 'BVC3') throw new Error('not a bvc3d blob');
  const length = new DataView(buffer).getUint32(4, true);
  const header = JSON.parse(new TextDecoder().decode(bytes.subarray(8, 8 + length)));
  const base = 8 + length;
  const arrays = {};
  for (const a of header.arrays) {
    const T = typed[a.dtype];
    arrays[a.name] = new T(buffer, base + a.offset, a.bytes / T.BYTES_PER_ELEMENT);
    arrays[a.name].shape = a.shape;
  }
  return { header, arrays };
}

function base64Bytes(b64) {
  const text = atob(b64);
  const out = new Uint8Array(text.length);
  for (let i = 0; i < text.length; i++) out[i] = text.charCodeAt(i);
  return out.buffer;
}

const loading = new Map();
function loadScript(name) {
  if (!loading.has(name)) {
    loading.set(name, new Promise((resolve, reject) => {
      const s = document.createElement('script');
      s.src = `data/${name}`;
      s.onload = resolve;
      s.onerror = () => reject(new Error(`cannot load data/${name}`));
      document.head.appendChild(s);
    }));
  }
  return loading.get(name);
}

async function exportedReply(endpoint, params) {
  if (endpoint === 'index') return { status: 200, type: 'application/json', body: JSON.stringify(exported.index) };
  const key = requestKey(endpoint, params);
  const name = exported.files[key];
  if (!name) throw new RequestError(404, `not in this export: ${key}`);
  await loadScript(name);
  const r = exported.data[key];
  const buffer = base64Bytes(r.b64);
  return { status: r.status, type: r.type, body: buffer };
}

// The samples an export holds step data for ("#recording" for a recording's scans); null when served.
export function exportedSteps(path) {
  return exported ? exported.steps[path] || [] : null;
}

// GET a reply: JSON replies as objects, blobs decoded. Errors throw RequestError with the message.
export async function get(endpoint, params = {}) {
  let status, type, body;
  if (exported) {
    ({ status, type, body } = await exportedReply(endpoint, params));
  } else {
    const query = new URLSearchParams(params).toString();
    const res = await fetch(`api/${endpoint}${query ? `?${query}` : ''}`);
    status = res.status;
    type = res.headers.get('content-type') || '';
    body = await res.arrayBuffer();
  }
  const isJson = type.startsWith('application/json');
  if (status !== 200) {
    let message = `error ${status}`;
    try {
      message = JSON.parse(new TextDecoder().decode(body)).error;
    } catch (e) { /* not JSON */ }
    throw new RequestError(status, message);
  }
  if (isJson) return JSON.parse(typeof body === 'string' ? body : new TextDecoder().decode(body));
  return decodeBlob(body);
}
