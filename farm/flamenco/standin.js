// A stand-in for the part of Flamenco 3's job-compiler API that tempera.js
// uses (the global `author`, and the `job` handed to compileJob), recording
// what a compiled job holds: tasks in order, their type, commands and
// dependencies. Used by tempera.test.js and tests/python/test_farm.py.

function makeAuthor() {
    return {
        Task(name, type) {
            if (typeof name !== "string" || !name) throw new Error("author.Task needs a name");
            return {
                name, type, commands: [], dependencies: [],
                addCommand(command) { this.commands.push(command); },
                addDependency(task) {
                    if (!task || typeof task.name !== "string") throw new Error("addDependency needs a task");
                    this.dependencies.push(task);
                },
            };
        },
        Command(name, parameters) { return { name, parameters }; },
    };
}

function makeJob(settings) {
    return {
        settings, tasks: [],
        addTask(task) {
            if (this.tasks.some((t) => t.name === task.name)) throw new Error(`duplicate task name ${task.name}`);
            for (const dep of task.dependencies) {
                if (!this.tasks.includes(dep)) throw new Error(`${task.name} depends on ${dep.name}, not added before it`);
            }
            this.tasks.push(task);
        },
    };
}

// A compiled job as plain data: [{name, type, argv (of its first command), commands, depends}].
function summary(job) {
    return job.tasks.map((t) => ({
        name: t.name, type: t.type,
        argv: t.commands.length ? [t.commands[0].parameters.exe].concat(t.commands[0].parameters.args) : [],
        commands: t.commands.map((c) => c.name),
        depends: t.dependencies.map((d) => d.name),
    }));
}

// Loads tempera.js with a fresh stand-in `author` and compiles `settings`.
function compile(settings) {
    global.author = makeAuthor();
    const path = require.resolve("./tempera.js");
    delete require.cache[path];
    const jobType = require(path);
    const job = makeJob(settings);
    jobType.compileJob(job);
    return { job, jobType };
}

module.exports = { makeAuthor, makeJob, summary, compile };
