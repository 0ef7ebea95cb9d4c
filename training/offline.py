"""Ultralytics without a network: import this module before `ultralytics`.

Sets YOLO_OFFLINE / YOLO_AUTOINSTALL, a project-local config folder (`training/.ultralytics`,
git-ignored), settings sync off, and DejaVuSans standing in for the Arial fonts Ultralytics
would otherwise download for its plots.
"""

import os
import shutil
from pathlib import Path

HERE = Path(__file__).resolve().parent
CONFIG = HERE / ".ultralytics"

os.environ["YOLO_OFFLINE"] = "1"
os.environ["YOLO_AUTOINSTALL"] = "0"
os.environ["YOLO_CONFIG_DIR"] = str(CONFIG)
(CONFIG / "Ultralytics").mkdir(parents=True, exist_ok=True)

import matplotlib  # noqa: E402

_font = Path(matplotlib.get_data_path()) / "fonts" / "ttf" / "DejaVuSans.ttf"
for name in ("Arial.ttf", "Arial.Unicode.ttf"):
    dest = CONFIG / "Ultralytics" / name
    if not dest.exists():
        shutil.copy(_font, dest)

from ultralytics.utils import SETTINGS  # noqa: E402

SETTINGS.update({"sync": False, "hub": False} if "hub" in SETTINGS else {"sync": False})
