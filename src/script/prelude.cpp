#include "script/prelude.h"

namespace vr {

// Natives the host defines before this runs: __nodeType(id), __nodeFieldType(id, name),
// __nodeGet(id, name) (a flat array), __nodeSet(id, name, flat), __createNodes(text, x3d),
// __addRoute/__deleteRoute(fromId, fromField, toId, toField), __print(text), __now(), __warn(text).
const char* const kScriptPrelude = R"JS(
(function (g) {
'use strict';
function def(C, proto, names) {
    C.prototype = proto;
    proto.constructor = C;
    names.forEach(function (n, i) {
        Object.defineProperty(proto, String(i), {
            get: function () { return this[n]; },
            set: function (v) { this[n] = +v; } });
    });
    proto.toString = function () {
        var self = this;
        return names.map(function (n) { return String(self[n]); }).join(' ');
    };
}
function vecClass(names) {
    var C = function () {
        var self = this instanceof C ? this : Object.create(C.prototype);
        for (var i = 0; i < names.length; ++i) self[names[i]] = arguments.length > i ? +arguments[i] : 0;
        return self;
    };
    var make = function (values) { return C.apply(null, values); };
    var comps = function (v) { return names.map(function (n) { return v[n]; }); };
    var proto = {
        add: function (v) { var a = comps(this), b = comps(v); return make(a.map(function (x, i) { return x + b[i]; })); },
        subtract: function (v) { var a = comps(this), b = comps(v); return make(a.map(function (x, i) { return x - b[i]; })); },
        multiply: function (s) { return make(comps(this).map(function (x) { return x * s; })); },
        divide: function (s) { return make(comps(this).map(function (x) { return x / s; })); },
        dot: function (v) { var a = comps(this), b = comps(v), d = 0; for (var i = 0; i < a.length; ++i) d += a[i] * b[i]; return d; },
        length: function () { return Math.sqrt(this.dot(this)); },
        normalize: function () { var l = this.length(); return l > 0 ? this.divide(l) : make(comps(this)); },
        negate: function () { return make(comps(this).map(function (x) { return -x; })); }
    };
    def(C, proto, names);
    return C;
}
var SFVec2f = vecClass(['x', 'y']), SFVec3f = vecClass(['x', 'y', 'z']), SFVec4f = vecClass(['x', 'y', 'z', 'w']);
var SFVec2d = vecClass(['x', 'y']), SFVec3d = vecClass(['x', 'y', 'z']), SFVec4d = vecClass(['x', 'y', 'z', 'w']);
SFVec3f.prototype.cross = SFVec3d.prototype.cross = function (v) {
    return new this.constructor(this.y * v.z - this.z * v.y, this.z * v.x - this.x * v.z, this.x * v.y - this.y * v.x);
};

function SFColor(r, g, b) {
    var self = this instanceof SFColor ? this : Object.create(SFColor.prototype);
    self.r = +(r || 0); self.g = +(g || 0); self.b = +(b || 0);
    return self;
}
def(SFColor, {
    // Hue in degrees [0, 360), saturation and value in [0, 1] (VRML97 Annex C.6.5; X_ITE's rule).
    setHSV: function (h, s, v) {
        h = ((+h % 360) + 360) % 360 / 60; s = +s; v = +v;
        var i = Math.floor(h), f = h - i, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
        var rgb = [[v, t, p], [q, v, p], [p, v, t], [p, q, v], [t, p, v], [v, p, q]][i % 6];
        this.r = rgb[0]; this.g = rgb[1]; this.b = rgb[2];
    },
    getHSV: function () {
        var mx = Math.max(this.r, this.g, this.b), mn = Math.min(this.r, this.g, this.b), d = mx - mn, h = 0;
        if (d > 0) {
            if (mx === this.r) h = ((this.g - this.b) / d) % 6;
            else if (mx === this.g) h = (this.b - this.r) / d + 2;
            else h = (this.r - this.g) / d + 4;
            h *= 60; if (h < 0) h += 360;
        }
        return [h, mx > 0 ? d / mx : 0, mx];
    }
}, ['r', 'g', 'b']);
function SFColorRGBA(r, g, b, a) {
    var self = this instanceof SFColorRGBA ? this : Object.create(SFColorRGBA.prototype);
    self.r = +(r || 0); self.g = +(g || 0); self.b = +(b || 0); self.a = +(a || 0);
    return self;
}
def(SFColorRGBA, {}, ['r', 'g', 'b', 'a']);

// Rotations as unit quaternions [x, y, z, w].
function quat(r) {
    var l = Math.sqrt(r.x * r.x + r.y * r.y + r.z * r.z), s = Math.sin(r.angle / 2);
    if (l === 0) return [0, 0, 0, 1];
    return [r.x / l * s, r.y / l * s, r.z / l * s, Math.cos(r.angle / 2)];
}
function fromQuat(q) {
    var w = Math.max(-1, Math.min(1, q[3])), s = Math.sqrt(Math.max(0, 1 - w * w));
    if (s < 1e-12) return new SFRotation(0, 0, 1, 0);
    return new SFRotation(q[0] / s, q[1] / s, q[2] / s, 2 * Math.acos(w));
}
function qmul(a, b) {  // a * b: b applied first, then a
    return [a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
            a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
            a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
            a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2]];
}
function SFRotation(a, b, c, d) {
    var self = this instanceof SFRotation ? this : Object.create(SFRotation.prototype);
    if (a instanceof SFVec3f && b instanceof SFVec3f) {  // the rotation taking a onto b
        var u = a.normalize(), v = b.normalize(), axis = u.cross(v), sn = axis.length(), cs = u.dot(v);
        if (sn < 1e-12) {
            if (cs > 0) axis = new SFVec3f(0, 0, 1);
            else { axis = u.cross(new SFVec3f(1, 0, 0)); if (axis.length() < 1e-6) axis = u.cross(new SFVec3f(0, 1, 0)); }
        }
        axis = axis.normalize();
        self.x = axis.x; self.y = axis.y; self.z = axis.z; self.angle = Math.atan2(sn, cs);
    } else if (a instanceof SFVec3f) {
        self.x = a.x; self.y = a.y; self.z = a.z; self.angle = +(b || 0);
    } else {
        self.x = arguments.length > 0 ? +a : 0; self.y = arguments.length > 1 ? +b : 0;
        self.z = arguments.length > 2 ? +c : 1; self.angle = arguments.length > 3 ? +d : 0;
    }
    return self;
}
def(SFRotation, {
    getAxis: function () { return new SFVec3f(this.x, this.y, this.z); },
    setAxis: function (v) { this.x = v.x; this.y = v.y; this.z = v.z; },
    inverse: function () { var q = quat(this); return fromQuat([-q[0], -q[1], -q[2], q[3]]); },
    // r1.multiply(r2): r1 first, then r2 (as X_ITE composes them).
    multiply: function (r) { return fromQuat(qmul(quat(r), quat(this))); },
    multVec: function (v) {
        var q = quat(this), p = qmul(qmul(q, [v.x, v.y, v.z, 0]), [-q[0], -q[1], -q[2], q[3]]);
        return new v.constructor(p[0], p[1], p[2]);
    },
    slerp: function (r, t) {
        var a = quat(this), b = quat(r), c = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
        if (c < 0) { b = b.map(function (x) { return -x; }); c = -c; }
        var wa = 1 - t, wb = t;
        if (c < 0.9999995) { var o = Math.acos(c), s = Math.sin(o); wa = Math.sin((1 - t) * o) / s; wb = Math.sin(t * o) / s; }
        return fromQuat(a.map(function (x, i) { return wa * x + wb * b[i]; }));
    }
}, ['x', 'y', 'z', 'angle']);

function SFImage(w, h, comp, array) {
    var self = this instanceof SFImage ? this : Object.create(SFImage.prototype);
    self.width = +(w || 0); self.height = +(h || 0); self.comp = +(comp || 0);
    self.array = array ? MFInt32.apply(null, Array.prototype.slice.call(array)) : new MFInt32();
    return self;
}
SFImage.prototype.toString = function () { return this.width + ' ' + this.height + ' ' + this.comp + ' ' + Array.prototype.join.call(this.array, ' '); };

// MF arrays: real arrays (index, length, push) of their SF values.
function mfClass(convert) {
    var C = function () {
        var a = Array.prototype.slice.call(arguments).map(convert);
        Object.setPrototypeOf(a, C.prototype);
        return a;
    };
    C.prototype = Object.create(Array.prototype);
    C.prototype.constructor = C;
    C.prototype.toString = function () { return Array.prototype.map.call(this, String).join(', '); };
    return C;
}
var toNum = function (x) { return +x; }, same = function (x) { return x; };
var MFFloat = mfClass(toNum), MFDouble = mfClass(toNum), MFTime = mfClass(toNum);
var MFInt32 = mfClass(function (x) { return x | 0; }), MFBool = mfClass(function (x) { return !!x; });
var MFString = mfClass(String), MFNode = mfClass(same);
var MFVec2f = mfClass(same), MFVec3f = mfClass(same), MFVec4f = mfClass(same), MFRotation = mfClass(same);
var MFVec2d = mfClass(same), MFVec3d = mfClass(same), MFVec4d = mfClass(same);
var MFColor = mfClass(same), MFColorRGBA = mfClass(same), MFImage = mfClass(same);

// SFNode: a proxy whose properties are the node's fields (reading them; setting them is
// directOutput). One proxy a node, so that == compares nodes. A field read during a call is one
// live object until the call ends (a loop over geometry.height reads the node once), and what
// the script changed in it is written back then, as a browser's field objects are live.
var proxies = {}, live = {};
function flush() {
    var held = live;
    live = {};
    Object.keys(held).forEach(function (key) {
        var e = held[key], now = flat(e.type, e.value);
        if (JSON.stringify(now) !== e.before) __nodeSet(e.id, e.name, now);
    });
}
function node(id) {
    if (id < 0) return null;
    if (proxies[id]) return proxies[id];
    var p = new Proxy({ __id: id }, {
        get: function (t, k) {
            if (k === '__id') return id;
            if (typeof k !== 'string') return undefined;
            if (k === 'toString') return function () { return __nodeType(id) + ' { }'; };
            if (k === 'getNodeName' || k === 'getTypeName') return function () { return __nodeType(id); };
            if (k === 'toVRMLString' || k === 'toX3DString') return function () { return __nodeType(id) + ' { }'; };
            if (k === 'toXMLString') return function () { return '<' + __nodeType(id) + '/>'; };
            if (k === 'valueOf') return function () { return p; };
            var key = id + '/' + k;
            if (live[key]) return live[key].value;
            var type = __nodeFieldType(id, k);
            if (!type) return undefined;
            var a = __nodeGet(id, k), value = make(type, a);
            if (value !== null && typeof value === 'object' && !(value.__id >= 0))
                live[key] = { id: id, name: k, type: type, value: value, before: JSON.stringify(a) };
            return value;
        },
        set: function (t, k, v) {
            delete live[id + '/' + String(k)];
            var type = __nodeFieldType(id, String(k));
            if (!type) { __warn('node ' + __nodeType(id) + ' has no field ' + String(k) + ' to set'); return true; }
            __nodeSet(id, String(k), flat(type, v));
            return true;
        }
    });
    proxies[id] = p;
    return p;
}
function SFNode(text) {
    var nodes = __createNodes(String(text || ''), false);
    return nodes.length ? node(nodes[0]) : null;
}

var vecs = { Vec2f: SFVec2f, Vec3f: SFVec3f, Vec4f: SFVec4f, Vec2d: SFVec2d, Vec3d: SFVec3d, Vec4d: SFVec4d,
             Rotation: SFRotation, Color: SFColor, ColorRGBA: SFColorRGBA };
var sizes = { Vec2f: 2, Vec3f: 3, Vec4f: 4, Vec2d: 2, Vec3d: 3, Vec4d: 4, Rotation: 4, Color: 3, ColorRGBA: 4,
              Matrix3f: 9, Matrix3d: 9, Matrix4f: 16, Matrix4d: 16 };
var mfs = { Float: MFFloat, Double: MFDouble, Time: MFTime, Int32: MFInt32, Bool: MFBool, String: MFString,
            Node: MFNode, Vec2f: MFVec2f, Vec3f: MFVec3f, Vec4f: MFVec4f, Vec2d: MFVec2d, Vec3d: MFVec3d,
            Vec4d: MFVec4d, Rotation: MFRotation, Color: MFColor, ColorRGBA: MFColorRGBA };
function scalar(base, x) {
    if (base === 'Bool') return !!x;
    if (base === 'String') return x === undefined ? '' : String(x);
    if (base === 'Node') return node(x === undefined ? -1 : x);
    if (base === 'Int32') return (x || 0) | 0;
    return +(x || 0);
}
// A value of `type` ("SFVec3f", "MFNode", ...) from the host's flat array of numbers, strings or
// node ids (-1: NULL).
function make(type, a) {
    var base = type.slice(2), multi = type[1] === 'F' && type[0] === 'M';
    if (base === 'Image') {
        if (multi) return new MFImage();
        return new SFImage(a[0], a[1], a[2], a.slice(3));
    }
    var n = sizes[base] || 1, C = vecs[base], values = [];
    for (var i = 0; i + n <= a.length || (!multi && i === 0); i += n) {
        var part = a.slice(i, i + n);
        values.push(C ? C.apply(null, part.length === n ? part : []) : n > 1 ? part : scalar(base, part[0]));
        if (!multi) break;
    }
    if (!multi) return values[0];
    var M = mfs[base] || MFFloat, r = M();
    for (var k = 0; k < values.length; ++k) r.push(values[k]);
    return r;
}
function flatOne(base, v, out) {
    var n = sizes[base] || 1;
    if (base === 'Node') { out.push(v && v.__id !== undefined ? v.__id : -1); return; }
    if (base === 'String') { out.push(v === undefined || v === null ? '' : String(v)); return; }
    if (base === 'Bool') { out.push(v ? 1 : 0); return; }
    if (n === 1) { var x = +v; out.push(base === 'Int32' ? x | 0 : x); return; }
    for (var i = 0; i < n; ++i) out.push(+v[i]);
}
// The host's flat array of a value given as `type`.
function flat(type, v) {
    var base = type.slice(2), multi = type[0] === 'M', out = [];
    if (base === 'Image') {
        if (multi || !v) return [0, 0, 0];
        out = [v.width | 0, v.height | 0, v.comp | 0];
        for (var p = 0; p < v.array.length; ++p) out.push(v.array[p] | 0);
        return out;
    }
    if (!multi) { flatOne(base, v, out); return out; }
    if (v === null || v === undefined) return out;
    if (typeof v !== 'object' || v.__id !== undefined || !('length' in v) || typeof v.length !== 'number') v = [v];
    for (var i = 0; i < v.length; ++i) flatOne(base, v[i], out);
    return out;
}

// The Script's own fields: globals whose setters keep the declared type, and whose eventOuts
// are sent when assigned, or changed in place, during a call.
var fields = {}, types = {}, outs = [], assigned = {}, snapshot = {};
g.__declare = function (name, type, isOut, a) {
    types[name] = type;
    fields[name] = make(type, a);
    if (isOut) outs.push(name);
    Object.defineProperty(g, name, {
        get: function () { return fields[name]; },
        set: function (v) { fields[name] = make(type, flat(type, v)); if (isOut) assigned[name] = true; },
        configurable: true });
};
// One call: the field of an input event takes its value, then the function of that name (set_x,
// x) runs with (value, timestamp); returns [name, flat] of each eventOut sent.
g.__call = function (fn, field, type, a, ts) {
    assigned = {};
    live = {};
    outs.forEach(function (n) { snapshot[n] = JSON.stringify(flat(types[n], fields[n])); });
    var value = type ? make(type, a) : undefined;
    if (field && types[field]) fields[field] = value;
    var f = g[fn];
    if (typeof f === 'function') f.call(g, value, ts);
    flush();
    var sent = [];
    outs.forEach(function (n) {
        var now = flat(types[n], fields[n]);
        if (assigned[n] || JSON.stringify(now) !== snapshot[n]) sent.push([n, now]);
    });
    return sent;
};
g.__hasFunction = function (fn) { return typeof g[fn] === 'function'; };

var Browser = {
    getName: function () { return 'vrmlray'; },
    getVersion: function () { return __version(); },
    getCurrentTime: function () { return __now(); },
    getCurrentSpeed: function () { return 0; },
    getCurrentFrameRate: function () { return 0; },
    getWorldURL: function () { return __worldUrl(); },
    print: function () { __print(Array.prototype.join.call(arguments, ' ')); },
    println: function () { __print(Array.prototype.join.call(arguments, ' ')); },
    createVrmlFromString: function (s) { return MFNode.apply(null, __createNodes(String(s), false).map(node)); },
    createX3DFromString: function (s) { return MFNode.apply(null, __createNodes(String(s), true).map(node)); },
    addRoute: function (a, af, b, bf) { __route(true, a ? a.__id : -1, String(af), b ? b.__id : -1, String(bf)); },
    deleteRoute: function (a, af, b, bf) { __route(false, a ? a.__id : -1, String(af), b ? b.__id : -1, String(bf)); },
    loadURL: function () { __warn('Browser.loadURL does nothing in vrmlray (no world is replaced)'); },
    replaceWorld: function () { __warn('Browser.replaceWorld does nothing in vrmlray (no world is replaced)'); },
    createVrmlFromURL: function () { __warn('Browser.createVrmlFromURL does nothing in vrmlray'); },
    setDescription: function () {},
    setBrowserOption: function () {},
    getBrowserOption: function () { return undefined; }
};
// X3D's properties of the same (ISO/IEC 19777-1 7.2).
Object.defineProperty(Browser, 'name', { get: function () { return Browser.getName(); } });
Object.defineProperty(Browser, 'version', { get: function () { return Browser.getVersion(); } });
Object.defineProperty(Browser, 'currentTime', { get: function () { return __now(); } });
Object.defineProperty(Browser, 'currentSpeed', { get: function () { return 0; } });
Object.defineProperty(Browser, 'currentFrameRate', { get: function () { return 0; } });
// X3D's scene (19777-1 7.4): what a script reads of it, and createNode; it adds or removes no root
// node. A call of a member vrmlray lacks is one warning naming it (and it gives undefined, so the
// script's next use of it throws).
var currentScene = {
    getNamedNode: function (n) {
        var id = __namedNode(String(n));
        if (id < 0) throw new Error('no node named ' + n);
        return node(id);
    },
    createNode: function (type) {
        var ids = __createNodes(String(type) + ' {}', true);
        return ids.length ? node(ids[0]) : null;
    },
    toVRMLString: function () { return __sceneText(false); },
    toXMLString: function () { return __sceneText(true); }
};
['createProto', 'updateNamedNode', 'removeNamedNode', 'getImportedNode', 'updateImportedNode',
 'removeImportedNode', 'addRootNode', 'removeRootNode', 'getExportedNode', 'addRoute', 'deleteRoute',
 'getMetaData', 'setMetaData'].forEach(function (name) {
    currentScene[name] = function () {
        __warn('Browser.currentScene.' + name + ' is not supported by vrmlray');
    };
});
['protos', 'externprotos', 'routes'].forEach(function (name) {
    Object.defineProperty(currentScene, name, { get: function () {
        __warn('Browser.currentScene.' + name + ' is not supported by vrmlray');
        return undefined;
    } });
});
Object.defineProperty(currentScene, 'rootNodes', { get: function () { return MFNode.apply(null, __rootNodes().map(node)); } });
Object.defineProperty(currentScene, 'worldURL', { get: function () { return __worldUrl(); } });
Object.defineProperty(Browser, 'currentScene', { get: function () { return currentScene; } });
g.Browser = Browser;
g.print = Browser.print;
g.println = Browser.println;
[['SFVec2f', SFVec2f], ['SFVec3f', SFVec3f], ['SFVec4f', SFVec4f], ['SFVec2d', SFVec2d], ['SFVec3d', SFVec3d],
 ['SFVec4d', SFVec4d], ['SFColor', SFColor], ['SFColorRGBA', SFColorRGBA], ['SFRotation', SFRotation],
 ['SFImage', SFImage], ['SFNode', SFNode], ['MFFloat', MFFloat], ['MFDouble', MFDouble], ['MFTime', MFTime],
 ['MFInt32', MFInt32], ['MFBool', MFBool], ['MFString', MFString], ['MFNode', MFNode], ['MFVec2f', MFVec2f],
 ['MFVec3f', MFVec3f], ['MFVec4f', MFVec4f], ['MFVec2d', MFVec2d], ['MFVec3d', MFVec3d], ['MFVec4d', MFVec4d],
 ['MFRotation', MFRotation], ['MFColor', MFColor], ['MFColorRGBA', MFColorRGBA], ['MFImage', MFImage]
].forEach(function (p) { g[p[0]] = p[1]; });
g.TRUE = true;
g.FALSE = false;
})(this);
)JS";

}  // namespace vr
