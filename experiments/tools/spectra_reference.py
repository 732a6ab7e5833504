"""Reference RGB values for mltbench's spectrum conversion, computed by Mitsuba 3.

mltbench converts `<spectrum>` values to RGB the way Mitsuba 3's RGB variants do
(src/scene/spectra.rs). This script asks Mitsuba itself, through its XML parser, what RGB a
few spectra become, so that tests/spectra.rs can compare against an independent reference.

    python3 -m venv /work/venv-mitsuba
    /work/venv-mitsuba/bin/pip install "mitsuba>=3.9,<3.10" numpy
    /work/venv-mitsuba/bin/python experiments/tools/spectra_reference.py            # test spectra
    /work/venv-mitsuba/bin/python experiments/tools/spectra_reference.py conductors # named metals

The numbers in tests/spectra.rs and the named-conductor table in src/scene/spectra.rs were
produced with Mitsuba 3.9.1 (drjit 1.5.0), variant scalar_rgb.
"""

import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")
# Mitsuba warns when it clamps a colour; the clamping is part of what is being measured.
mi.set_log_level(mi.LogLevel.Error)

# The Cornell box's measured reflectances and light (as distributed with the Cornell box scene).
CBOX_WHITE = "400:0.343, 404:0.445, 408:0.551, 412:0.624, 416:0.665, 420:0.687, 424:0.708, 428:0.723, 432:0.715, 436:0.71, 440:0.745, 444:0.758, 448:0.739, 452:0.767, 456:0.777, 460:0.765, 464:0.751, 468:0.745, 472:0.748, 476:0.729, 480:0.745, 484:0.757, 488:0.753, 492:0.75, 496:0.746, 500:0.747, 504:0.735, 508:0.732, 512:0.739, 516:0.734, 520:0.725, 524:0.721, 528:0.733, 532:0.725, 536:0.732, 540:0.743, 544:0.744, 548:0.748, 552:0.728, 556:0.716, 560:0.733, 564:0.726, 568:0.713, 572:0.74, 576:0.754, 580:0.764, 584:0.752, 588:0.736, 592:0.734, 596:0.741, 600:0.74, 604:0.732, 608:0.745, 612:0.755, 616:0.751, 620:0.744, 624:0.731, 628:0.733, 632:0.744, 636:0.731, 640:0.712, 644:0.708, 648:0.729, 652:0.73, 656:0.727, 660:0.707, 664:0.703, 668:0.729, 672:0.75, 676:0.76, 680:0.751, 684:0.739, 688:0.724, 692:0.73, 696:0.74, 700:0.737"
CBOX_RED = "400:0.04, 404:0.046, 408:0.048, 412:0.053, 416:0.049, 420:0.05, 424:0.053, 428:0.055, 432:0.057, 436:0.056, 440:0.059, 444:0.057, 448:0.061, 452:0.061, 456:0.06, 460:0.062, 464:0.062, 468:0.062, 472:0.061, 476:0.062, 480:0.06, 484:0.059, 488:0.057, 492:0.058, 496:0.058, 500:0.058, 504:0.056, 508:0.055, 512:0.056, 516:0.059, 520:0.057, 524:0.055, 528:0.059, 532:0.059, 536:0.058, 540:0.059, 544:0.061, 548:0.061, 552:0.063, 556:0.063, 560:0.067, 564:0.068, 568:0.072, 572:0.08, 576:0.09, 580:0.099, 584:0.124, 588:0.154, 592:0.192, 596:0.255, 600:0.287, 604:0.349, 608:0.402, 612:0.443, 616:0.487, 620:0.513, 624:0.558, 628:0.584, 632:0.62, 636:0.606, 640:0.609, 644:0.651, 648:0.612, 652:0.61, 656:0.65, 660:0.638, 664:0.627, 668:0.62, 672:0.63, 676:0.628, 680:0.642, 684:0.639, 688:0.657, 692:0.639, 696:0.635, 700:0.642"
CBOX_GREEN = "400:0.092, 404:0.096, 408:0.098, 412:0.097, 416:0.098, 420:0.095, 424:0.095, 428:0.097, 432:0.095, 436:0.094, 440:0.097, 444:0.098, 448:0.096, 452:0.101, 456:0.103, 460:0.104, 464:0.107, 468:0.109, 472:0.112, 476:0.115, 480:0.125, 484:0.14, 488:0.16, 492:0.187, 496:0.229, 500:0.285, 504:0.343, 508:0.39, 512:0.435, 516:0.464, 520:0.472, 524:0.476, 528:0.481, 532:0.462, 536:0.447, 540:0.441, 544:0.426, 548:0.406, 552:0.373, 556:0.347, 560:0.337, 564:0.314, 568:0.285, 572:0.277, 576:0.266, 580:0.25, 584:0.23, 588:0.207, 592:0.186, 596:0.171, 600:0.16, 604:0.148, 608:0.141, 612:0.136, 616:0.13, 620:0.126, 624:0.123, 628:0.121, 632:0.122, 636:0.119, 640:0.114, 644:0.115, 648:0.117, 652:0.117, 656:0.118, 660:0.12, 664:0.122, 668:0.128, 672:0.132, 676:0.139, 680:0.144, 684:0.146, 688:0.15, 692:0.152, 696:0.157, 700:0.159"
CBOX_LIGHT = "400:0, 500:8, 600:15.6, 700:18.4"

# (name, usage, spectrum). Usage says where the spectrum sits in a scene, which is what
# decides Mitsuba's treatment: a diffuse reflectance, an emitter's radiance, or a
# conductor's eta (one of the "unbounded" properties).
SPECTRA = [
    ("cbox_white", "Reflectance", CBOX_WHITE),
    ("cbox_red", "Reflectance", CBOX_RED),
    ("cbox_green", "Reflectance", CBOX_GREEN),
    ("constant_half", "Reflectance", "360:0.5, 830:0.5"),
    ("band_450_650", "Reflectance", "450:1, 650:1"),
    ("green_peak", "Reflectance", "500:0, 520:1, 540:0"),
    ("bright_red", "Reflectance", "580:0, 600:5, 640:5, 660:0"),
    ("cbox_light", "Emission", CBOX_LIGHT),
    ("constant_half", "Emission", "360:0.5, 830:0.5"),
    ("blue_line", "Emission", "440:0, 450:10, 460:0"),
    ("constant_half", "Unbounded", "360:0.5, 830:0.5"),
    ("rising_eta", "Unbounded", "400:0.2, 700:1.5"),
    ("blue_line", "Unbounded", "440:0, 450:10, 460:0"),
]


def mitsuba_rgb(usage, spectrum):
    if usage == "Reflectance":
        xml = f'<bsdf version="3.0.0" type="diffuse"><spectrum name="reflectance" value="{spectrum}"/></bsdf>'
        key = "reflectance.value"
    elif usage == "Emission":
        xml = f'<emitter version="3.0.0" type="constant"><spectrum name="radiance" value="{spectrum}"/></emitter>'
        key = "radiance.value"
    else:
        xml = f'<bsdf version="3.0.0" type="conductor"><spectrum name="eta" value="{spectrum}"/></bsdf>'
        key = "eta.value"
    value = mi.traverse(mi.load_string(xml))[key]
    return [float(value[i]) for i in range(3)]


def print_test_references():
    for name, usage, spectrum in SPECTRA:
        r, g, b = mitsuba_rgb(usage, spectrum)
        print(f"{name:14} {usage:12} [{r:.7}, {g:.7}, {b:.7}]")


def print_conductor_table():
    import pathlib

    ior_dir = pathlib.Path(mi.__file__).parent / "data" / "ior"
    names = sorted(p.name[: -len(".eta.spd")] for p in ior_dir.glob("*.eta.spd"))
    for name in names:
        if not (ior_dir / f"{name}.k.spd").exists():
            continue
        params = mi.traverse(mi.load_dict({"type": "conductor", "material": name}))
        # Shortest decimal that reads back as the same f32.
        eta = ", ".join(str(np.float32(params["eta.value"][i])) for i in range(3))
        k = ", ".join(str(np.float32(params["k.value"][i])) for i in range(3))
        print(f'    ("{name}", [{eta}], [{k}]),')


if __name__ == "__main__":
    if sys.argv[1:] == ["conductors"]:
        print_conductor_table()
    else:
        print_test_references()
