#!/usr/bin/python3
"""Lays one kvasios-franka-handeye session (DIR/pose_NN/image.png + data.json) out as `selfcal detect` takes it
today: the images in one folder (pose_NN.png, links to the originals) and a selfcal poses list of the recorded
joint angles (joints_rad, libfranka's joint_pose). The recording itself is only read.

usage: kvasios_layout.py SESSION_DIR OUT_DIR [--verification N,N,...]
  writes OUT_DIR/images/pose_NN.png and OUT_DIR/poses.yaml; the named pose numbers get role: verification.
"""
import json
import os
import sys


def main(argv):
    if len(argv) < 3:
        print(__doc__, file=sys.stderr)
        return 2
    session, out = argv[1], argv[2]
    verification = set()
    if len(argv) == 5 and argv[3] == '--verification':
        verification = {int(v) for v in argv[4].split(',') if v}
    images = os.path.join(out, 'images')
    os.makedirs(images, exist_ok=True)
    lines = ['format: selfcal-poses', 'version: 1', 'poses:']
    folders = sorted(d for d in os.listdir(session) if d.startswith('pose_'))
    for folder in folders:
        number = int(folder.split('_')[1])
        with open(os.path.join(session, folder, 'data.json')) as f:
            joints = json.load(f)['joint_pose']
        name = f'{folder}.png'
        link = os.path.join(images, name)
        if not os.path.lexists(link):
            os.symlink(os.path.abspath(os.path.join(session, folder, 'image.png')), link)
        role = ', role: verification' if number in verification else ''
        values = ', '.join(repr(float(q)) for q in joints)
        lines.append(f'  - {{image: {name}, joints_rad: [{values}]{role}}}')
    with open(os.path.join(out, 'poses.yaml'), 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return 0


if __name__ == '__main__':
    sys.exit(main(sys.argv))
