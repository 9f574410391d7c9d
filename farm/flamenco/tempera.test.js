// Tests of the Flamenco job type under Node: node --test farm/flamenco/
const test = require("node:test");
const assert = require("node:assert/strict");
const { compile, summary } = require("./standin.js");

const SHOT = {
    frames: "1-48", chunk_size: 8, scene: "/shared/shot010.blend", exemplar: "/shared/style.png",
    exemplar_scene: "/shared/sphere.blend", out: "/shared/out", temporal: 0, video: true,
    guide_args: "--samples 32", stylize_args: "--quality preview", tempera: "tempera",
};

test("job type settings name what compileJob reads", () => {
    const { jobType } = compile(SHOT);
    const keys = jobType.JOB_TYPE.settings.map((s) => s.key);
    for (const key of Object.keys(SHOT)) assert.ok(keys.includes(key), key);
    assert.equal(jobType.JOB_TYPE.label, "Tempera Stylize");
});

test("a 48-frame shot becomes exemplar, 6 guide, 6 stylize chunks and a finish", () => {
    const tasks = summary(compile(SHOT).job);
    const ranges = ["1-8", "9-16", "17-24", "25-32", "33-40", "41-48"];
    assert.deepEqual(tasks.map((t) => t.name), ["exemplar-guides", ...ranges.map((r) => `guides ${r}`),
                                              ...ranges.map((r) => `stylize ${r}`), "finish"]);
    assert.ok(tasks.every((t) => t.commands.length === 1 && t.commands[0] === "exec"));
    assert.deepEqual(tasks[0].argv, ["tempera", "render-guides", "/shared/sphere.blend", "--frames", "1",
                                     "--out", "/shared/out/exemplar_guides", "--samples", "32"]);
    assert.deepEqual(tasks[2].argv, ["tempera", "render-guides", "/shared/shot010.blend", "--frames", "9-16",
                                     "--out", "/shared/out/guides", "--samples", "32"]);
    const stylize = tasks.find((t) => t.name === "stylize 17-24");
    assert.deepEqual(stylize.argv, ["tempera", "stylize", "--frames", "17-24", "--guides", "/shared/out/guides",
                                    "--exemplar", "/shared/style.png", "--exemplar-guides",
                                    "/shared/out/exemplar_guides", "--out", "/shared/out", "--temporal", "0.0", "--quality", "preview",
                                    "--no-video"]);
    assert.deepEqual(stylize.depends, ["exemplar-guides", "guides 17-24"]);
    const finish = tasks[tasks.length - 1];
    assert.deepEqual(finish.argv.slice(0, 4), ["tempera", "stylize", "--frames", "1-48"]);
    assert.ok(!finish.argv.includes("--no-video"));
    assert.deepEqual(finish.depends, ranges.map((r) => `stylize ${r}`));
});

test("uneven chunks and gaps keep every frame exactly once", () => {
    const tasks = summary(compile({ ...SHOT, frames: "1-10,15,20-21", chunk_size: 4 }).job);
    const stylize = tasks.filter((t) => t.name.startsWith("stylize"));
    assert.deepEqual(stylize.map((t) => t.name), ["stylize 1-4", "stylize 5-8", "stylize 9-10,15,20",
                                                  "stylize 21"]);
    assert.deepEqual(tasks.find((t) => t.name === "stylize 21").depends, ["exemplar-guides", "guides 21"]);
});

test("a temporal chain is one stylize task after every guide chunk", () => {
    const tasks = summary(compile({ ...SHOT, temporal: 0.5 }).job);
    const stylize = tasks.filter((t) => t.name.startsWith("stylize"));
    assert.equal(stylize.length, 1);
    assert.equal(stylize[0].name, "stylize 1-48");
    const at = stylize[0].argv.indexOf("--temporal");
    assert.deepEqual(stylize[0].argv.slice(at, at + 2), ["--temporal", "0.5"]);
    assert.deepEqual(stylize[0].depends, ["exemplar-guides", "guides 1-8", "guides 9-16", "guides 17-24",
                                          "guides 25-32", "guides 33-40", "guides 41-48"]);
});

test("from existing guide caches: no render tasks", () => {
    const tasks = summary(compile({ frames: "1-48", chunk_size: 16, guides: "/g", exemplar: "/s.png",
                                    exemplar_guides: "/eg", out: "/o", video: false }).job);
    assert.deepEqual(tasks.map((t) => t.name), ["stylize 1-16", "stylize 17-32", "stylize 33-48", "finish"]);
    assert.ok(tasks.every((t) => t.depends.length === 0 || t.name === "finish"));
    assert.ok(tasks[3].argv.includes("--no-video"));
});

test("bad settings are refused with a message naming the problem", () => {
    assert.throws(() => compile({ ...SHOT, frames: "1-x" }), /bad frame range '1-x'/);
    assert.throws(() => compile({ ...SHOT, frames: "9-3" }), /bad frame range '9-3'/);
    assert.throws(() => compile({ ...SHOT, exemplar_guides: "/eg" }), /exactly one of exemplar_guides/);
    assert.throws(() => compile({ ...SHOT, chunk_size: 0 }), /chunk size must be at least 1/);
    assert.throws(() => compile({ ...SHOT, scene: "" }), /scene \(.blend\) or as a guide cache/);
});
