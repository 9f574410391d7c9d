// Flamenco 3 job type "tempera": stylize a shot by example with Tempera's CLI.
//
// Install: copy this file into the Flamenco Manager's scripts/ folder (next to
// the flamenco-manager executable) and restart the manager; "Tempera Stylize"
// then appears among the job types. Every worker needs the `tempera` command
// (pip install tempera_native-*.whl, or build/bin/tempera) and, for jobs that
// render guides from a .blend, Blender (the manager's {blender} variable is not
// used: render-guides runs $TEMPERA_BLENDER or `blender`).
//
// The job becomes the same tasks as tempera.app.farm.plan() (addon/tempera/app/farm.py,
// which the tests compare against this file):
//   exemplar-guides   tempera render-guides EXEMPLAR.blend --frames N     (with an exemplar scene)
//   guides A-B        tempera render-guides SCENE.blend --frames A-B      (per chunk, with a scene)
//   stylize A-B       tempera stylize --guides ... --frames A-B --no-video (per chunk; with a temporal
//                     weight one task per segment, i.e. the whole shot until keyframes exist)
//   finish            tempera stylize over all frames: sheet and video (every frame is current)
// Each command resumes, so a task requeued after a worker died redoes only unfinished frames.

const JOB_TYPE = {
    label: "Tempera Stylize",
    description: "Stylize a shot by example: guide renders, StyLit synthesis, contact sheet and video",
    settings: [
        { key: "frames", type: "string", required: true, description: "Frames, e.g. 1-48 or 1-10,15",
          eval: "f'{C.scene.frame_start}-{C.scene.frame_end}'", evalInfo: { showLinkButton: true } },
        { key: "chunk_size", type: "int32", default: 8, description: "Frames per task" },
        { key: "scene", type: "string", subtype: "file_path", required: false,
          description: "The shot's .blend; its guides are rendered (empty: use 'guides')",
          eval: "bpy.data.filepath" },
        { key: "guides", type: "string", subtype: "dir_path", required: false,
          description: "The shot's guide cache (default: OUT/guides)" },
        { key: "exemplar", type: "string", subtype: "file_path", required: true,
          description: "The painted exemplar (style image)" },
        { key: "exemplar_guides", type: "string", subtype: "dir_path", required: false,
          description: "The exemplar's guide cache (or give 'exemplar_scene')" },
        { key: "exemplar_scene", type: "string", subtype: "file_path", required: false,
          description: "The exemplar's .blend, rendered into OUT/exemplar_guides" },
        { key: "exemplar_frame", type: "int32", default: 1, description: "Frame of the exemplar scene" },
        { key: "out", type: "string", subtype: "dir_path", required: true, description: "Output folder" },
        // The default is tempera's own (StylitOptions in stylit.hpp); tests/python/test_farm.py checks it.
        { key: "temporal", type: "float", default: 0.0, description: "Weight of the temporal guide (0 = frames independent)" },
        { key: "video", type: "bool", default: true, description: "Write stylized.mp4" },
        { key: "guide_args", type: "string", default: "", description: "Extra render-guides options" },
        { key: "stylize_args", type: "string", default: "", description: "Extra stylize options" },
        { key: "tempera", type: "string", default: "tempera", description: "The tempera command on the workers" },
    ],
};

function parseFrames(text) {
    const frames = new Set();
    for (const raw of String(text).split(",")) {
        const part = raw.trim();
        const range = /^(-?\d+)-(-?\d+)$/.exec(part);
        if (range) {
            const first = parseInt(range[1], 10), last = parseInt(range[2], 10);
            if (last < first) throw `bad frame range '${text}': expected e.g. '1-48' or '1-10,15'`;
            for (let f = first; f <= last; f++) frames.add(f);
        } else if (/^-?\d+$/.test(part)) {
            frames.add(parseInt(part, 10));
        } else {
            throw `bad frame range '${text}': expected e.g. '1-48' or '1-10,15'`;
        }
    }
    return Array.from(frames).sort((a, b) => a - b);
}

function formatFrames(frames) {
    const runs = [];
    let start = null;
    frames.forEach((f, i) => {
        if (start === null) start = f;
        if (i + 1 === frames.length || frames[i + 1] !== f + 1) {
            runs.push(start === f ? `${start}` : `${start}-${f}`);
            start = null;
        }
    });
    return runs.join(",");
}

function chunkFrames(frames, size) {
    if (!(size >= 1)) throw `chunk size must be at least 1, not ${size}`;
    const chunks = [];
    for (let i = 0; i < frames.length; i += size) chunks.push(frames.slice(i, i + size));
    return chunks;
}

function splitArgs(text) {
    return String(text || "").split(" ").filter((a) => a.length > 0);
}

// Python's repr() of a float, as tempera.app.farm writes the temporal weight.
function pyFloat(x) {
    return Number.isInteger(x) ? `${x}.0` : `${x}`;
}

function joinPath(dir, name) {
    return dir.endsWith("/") ? dir + name : `${dir}/${name}`;
}

function execCommand(tempera, args) {
    const words = splitArgs(tempera);
    return author.Command("exec", { exe: words[0], args: words.slice(1).concat(args) });
}

// The values of `name` in an argument list ("--key V" or "--key=V"), in order.
function optionValues(args, name) {
    const values = [];
    args.forEach((word, i) => {
        if (word === name && i + 1 < args.length) values.push(args[i + 1]);
        else if (word.startsWith(name + "=")) values.push(word.slice(name.length + 1));
    });
    return values;
}

// The methods this job type plans: those guided by light paths (the method registry's
// light_path_guides, native/include/tempera/methods/registry.hpp), whose settings are the
// ones above (the exemplar's guides, the temporal weight, the video). tempera.app.farm
// (Dask) plans every method.
const LIGHT_PATH_METHODS = ["stylit", "tcia"];

function checkMethod(args) {
    const methods = optionValues(args, "--method");
    const name = methods.length ? methods[methods.length - 1] : "stylit";
    if (!LIGHT_PATH_METHODS.includes(name))
        throw `the Flamenco job type plans stylit and tcia shots; run --method ${name} with ` +
            "'tempera farm' (Dask) or 'tempera stylize'";
}

// The frame of a --key text "F=PATH[,MASK]".
function keyFrame(text) {
    const number = text.split("=")[0];
    if (!/^-?[0-9]+$/.test(number)) throw `--key expects FRAME=PAINTING[,MASK], got '${text}'`;
    return parseInt(number, 10);
}

// The coherent method's segments: from key to key (the shot's --key and the layers'
// --layer-key NAME:F=PATH) and to the shot's ends; null for per-frame StyLit. The one copy
// of the job core's rule (native/include/tempera/app/segments.hpp) that cannot call it:
// the Flamenco manager runs no Tempera. tests/python/test_farm.py holds it to
// tempera.app.farm.shot_segments, which does.
function tciaSegments(frames, args) {
    const methods = optionValues(args, "--method");
    if (methods[methods.length - 1] !== "tcia") return null;
    const first = frames[0], last = frames[frames.length - 1];
    const bounds = new Set([first, last]);
    const keys = optionValues(args, "--key").map(keyFrame);
    for (const text of optionValues(args, "--layer-key")) {
        const colon = text.indexOf(":");
        if (colon <= 0) throw `--layer-key expects NAME:FRAME=PAINTING[,MASK], got '${text}'`;
        keys.push(keyFrame(text.slice(colon + 1)));
    }
    for (const k of keys) if (k > first && k < last) bounds.add(k);
    const sorted = [...bounds].sort((a, b) => a - b);
    if (sorted.length === 1) return [frames];
    const out = [];
    for (let i = 0; i + 1 < sorted.length; ++i) {
        const piece = [];
        for (let f = sorted[i]; f <= sorted[i + 1]; ++f) piece.push(f);
        out.push(piece);
    }
    return out;
}

function compileJob(job) {
    const s = job.settings;
    const frames = parseFrames(s.frames);
    const chunkSize = s.chunk_size === undefined ? 8 : s.chunk_size;
    const tempera = s.tempera || "tempera";
    if (!s.exemplar_guides === !s.exemplar_scene)
        throw "give the exemplar's guides as exactly one of exemplar_guides and exemplar_scene";
    if (!s.scene && !s.guides) throw "give the shot as a scene (.blend) or as a guide cache folder";
    const guides = s.guides || joinPath(s.out, "guides");
    const guideArgs = splitArgs(s.guide_args);

    let exemplarGuides = s.exemplar_guides;
    const exemplarTasks = [];
    if (s.exemplar_scene) {
        exemplarGuides = joinPath(s.out, "exemplar_guides");
        const frame = s.exemplar_frame === undefined ? 1 : s.exemplar_frame;
        const task = author.Task("exemplar-guides", "blender");
        task.addCommand(execCommand(tempera, ["render-guides", s.exemplar_scene, "--frames", `${frame}`,
                                              "--out", exemplarGuides].concat(guideArgs)));
        job.addTask(task);
        exemplarTasks.push(task);
    }

    const guideTasks = [];
    if (s.scene) {
        for (const chunk of chunkFrames(frames, chunkSize)) {
            const range = formatFrames(chunk);
            const task = author.Task(`guides ${range}`, "blender");
            task.addCommand(execCommand(tempera, ["render-guides", s.scene, "--frames", range,
                                                  "--out", guides].concat(guideArgs)));
            job.addTask(task);
            guideTasks.push({ frames: new Set(chunk), task: task });
        }
    }

    const stylizeArgs = splitArgs(s.stylize_args);
    checkMethod(stylizeArgs);
    const segments = tciaSegments(frames, stylizeArgs);
    // Always stated: the chunks must agree with a single run whatever the CLI's default. The
    // coherent method keeps its own (3; give --temporal W in stylize_args to change it).
    let common = ["--guides", guides, "--exemplar", s.exemplar, "--exemplar-guides", exemplarGuides,
                  "--out", s.out].concat(segments ? [] : ["--temporal", pyFloat(s.temporal)]);
    common = common.concat(stylizeArgs);
    // A temporal chain must not be cut: the whole shot is one task; the coherent method's
    // segments (key to key) are independent: one task each.
    const pieces = segments ? segments.map((p) => [p, ["--frames", formatFrames(frames), "--segment",
                                                       `${p[0]}-${p[p.length - 1]}`]])
        : (s.temporal ? [frames] : chunkFrames(frames, chunkSize)).map((p) => [p, ["--frames", formatFrames(p)]]);
    const stylizeTasks = [];
    for (const [piece, which] of pieces) {
        const range = formatFrames(piece);
        const task = author.Task(`stylize ${range}`, "misc");
        task.addCommand(execCommand(tempera, ["stylize"].concat(which, common, ["--no-video"])));
        for (const t of exemplarTasks) task.addDependency(t);
        for (const g of guideTasks) {
            if (piece.some((f) => g.frames.has(f))) task.addDependency(g.task);
        }
        job.addTask(task);
        stylizeTasks.push(task);
    }

    const finish = author.Task("finish", "misc");
    const video = s.video === undefined ? true : s.video;
    finish.addCommand(execCommand(tempera, ["stylize", "--frames", formatFrames(frames)].concat(
        common, video ? [] : ["--no-video"])));
    for (const t of stylizeTasks) finish.addDependency(t);
    job.addTask(finish);
}

// Flamenco's manager runs this file as a script (JOB_TYPE and compileJob are
// what it reads); under Node, the tests load it as a module.
if (typeof module !== "undefined") {
    module.exports = { JOB_TYPE, compileJob, parseFrames, formatFrames, chunkFrames };
}
