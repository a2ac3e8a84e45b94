"""How soon Ctrl-C gives control back during a long render through the Python module (not a test:
tests read no clock). The default scene at 1920x1080 and a 0.05% noise target, SIGINT after 4 s, RUNS
times (default 3); prints each latency and the median.
usage: PYTHONPATH=build/python [RUNS=3] /usr/bin/python3 tests/bench/python_interrupt.py SOURCE_DIR"""
import os, pathlib, shutil, signal, statistics, sys, tempfile, threading, time

import volmorph

scenes = pathlib.Path(sys.argv[1]) / "scenes"
latencies = []
for run in range(int(os.environ.get("RUNS", "3"))):
    with tempfile.TemporaryDirectory() as tmp:
        for sub in ("meshes", "skies"):
            os.symlink(scenes / sub, os.path.join(tmp, sub))
        path = pathlib.Path(tmp) / "shot.toml"
        text = (scenes / "bunny-to-knot.toml").read_text()
        path.write_text(text.replace("resolution = [480, 270]", "resolution = [1920, 1080]")
                        .replace("noise = 0.02", "noise = 0.0005").replace("samples = 6 ", "samples = 4096 "))
        scene = volmorph.Scene(path)
        sent = []

        def interrupt():
            time.sleep(4.0)
            sent.append(time.monotonic())
            os.kill(os.getpid(), signal.SIGINT)

        threading.Thread(target=interrupt, daemon=True).start()
        try:
            scene.render(12, path=os.path.join(tmp, "frame.exr"))
        except KeyboardInterrupt:
            latencies.append(time.monotonic() - sent[0])
            print("run {}: control back {:.3f} s after SIGINT".format(run + 1, latencies[-1]))
print("median {:.3f} s".format(statistics.median(latencies)))
