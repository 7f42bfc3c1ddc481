// The parts of three.js the 3-D view of eomgen's animation page uses.
export { WebGLRenderer, Scene, Color, PerspectiveCamera, DirectionalLight, AmbientLight, AxesHelper, Group, BoxGeometry, CylinderGeometry, SphereGeometry, MeshLambertMaterial, Mesh, BufferGeometry, BufferAttribute, LineSegments, LineBasicMaterial, Line } from 'three';
export { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
