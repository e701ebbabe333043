<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE TS>
<TS version="2.1" language="fr">
    <context>
        <name>TruOrtho</name>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Orientation</source>
            <translation>Orientation</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Orthophoto</source>
            <translation>Orthophoto</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Surface</source>
            <translation>Surface</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="21" />
            <source>Tools</source>
            <translation>Outils</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="158" />
            <source>Restore the colour edges of JPEGs with half-resolution colour</source>
            <translation>Restaurer les contours de couleur des JPEG à couleur sous-échantillonnée</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="170" />
            <source>Colour edges from the surface's height steps</source>
            <translation>Bords de couleur d'après les ruptures de hauteur de la surface</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="196" />
            <source>Run tiles on</source>
            <translation>Exécuter les tuiles sur</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="209" />
            <source>Dask scheduler address (tls://host:port or scheduler file; empty = TRUORTHO_DASK_SCHEDULER)</source>
            <translation>Adresse du planificateur Dask (tls://hôte:port ou fichier de planificateur ; vide = TRUORTHO_DASK_SCHEDULER)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="229" />
            <source>Ground control points</source>
            <translation>Points d'appui</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="235" />
            <source>GCP image measurements (table)</source>
            <translation>Mesures image des points d'appui (table)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="120" />
            <source>TruOrtho algorithms could not be loaded: {}</source>
            <translation>Les algorithmes TruOrtho n'ont pas pu être chargés : {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="172" />
            <source>off</source>
            <translation>non</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="173" />
            <source>checked: where the photos agree with the surface</source>
            <translation>vérifié : là où les photos s'accordent avec la surface</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="174" />
            <source>surface: at every height step (exact surfaces: LiDAR, building models)</source>
            <translation>surface : à chaque rupture de hauteur (surfaces exactes : LiDAR, modèles de bâtiments)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="198" />
            <source>inprocess: this process (all cores)</source>
            <translation>inprocess : ce processus (tous les cœurs)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="199" />
            <source>local: a Dask cluster of worker processes on this computer</source>
            <translation>local : une grappe Dask de processus de travail sur cet ordinateur</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/base.py" line="200" />
            <source>scheduler: a Dask scheduler (SCHEDULER_ADDRESS)</source>
            <translation>scheduler : un planificateur Dask (SCHEDULER_ADDRESS)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="42" />
            <source>Detect ground targets</source>
            <translation>Détecter les cibles au sol</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="73" />
            <source>Image folder</source>
            <translation>Dossier des images</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="79" />
            <source>Target type</source>
            <translation>Type de cible</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="87" />
            <source>ArUco dictionary</source>
            <translation>Dictionnaire ArUco</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="94" />
            <source>Marker IDs -&gt; GCP names (e.g. 0=GCP1,1=GCP2)</source>
            <translation>ID des marqueurs -&gt; noms des points d'appui (p. ex. 0=GCP1,1=GCP2)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="99" />
            <source>Orientation (TruOrtho JSON)</source>
            <translation>Orientation (JSON TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="110" />
            <source>Search radius around predicted positions (px)</source>
            <translation>Rayon de recherche autour des positions prédites (px)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="119" />
            <source>Minimum score (lower scores are flagged)</source>
            <translation>Score minimal (les scores inférieurs sont signalés)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="128" />
            <source>Refine by least-squares matching</source>
            <translation>Affiner par corrélation par moindres carrés</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="134" />
            <source>Target measurements (observation table)</source>
            <translation>Mesures des cibles (table d'observations)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="197" />
            <source>MARKER_IDS: give the mapping of marker IDs to GCP names, e.g. 0=GCP1,1=GCP2</source>
            <translation>MARKER_IDS : indiquez la correspondance entre ID des marqueurs et noms des points d'appui, p. ex. 0=GCP1,1=GCP2</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="212" />
            <source>{} measurements ({} flagged) in {} images</source>
            <translation>{} mesures ({} signalées) dans {} images</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>ArUco markers</source>
            <translation>Marqueurs ArUco</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>Circular targets</source>
            <translation>Cibles circulaires</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="80" />
            <source>Checkerboard (X) targets</source>
            <translation>Cibles en damier (X)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="194" />
            <source>{} predicted positions</source>
            <translation>{} positions prédites</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="149" />
            <source>MARKER_IDS: GCP name(s) {} are not in the GCP layer (it has {})</source>
            <translation>MARKER_IDS : le(s) nom(s) de point d'appui {} ne figure(nt) pas dans la couche des points d'appui (elle contient {})</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="182" />
            <source>{} targets are searched near their predicted positions: give ORIENTATION and GCPS</source>
            <translation>Les cibles {} sont cherchées près de leurs positions prédites : indiquez ORIENTATION et GCPS</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/detecttargets.py" line="190" />
            <source>No GCP projects into an image of {} with this orientation (the same photos?)</source>
            <translation>Aucun point d'appui ne se projette dans une image de {} avec cette orientation (les mêmes photos ?)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="32" />
            <source>Filter DSM (outliers, holes, smoothing, DTM)</source>
            <translation>Filtrer le MNS (valeurs aberrantes, trous, lissage, MNT)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="320" />
            <source>Filtered DSM</source>
            <translation>MNS filtré</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="81" />
            <source>Raw DSM</source>
            <translation>MNS brut</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="83" />
            <source>Confidence raster [0, 1]</source>
            <translation>Raster de confiance [0, 1]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="88" />
            <source>Outlier threshold (m; empty = 4 x resolution)</source>
            <translation>Seuil des valeurs aberrantes (m ; vide = 4 x la résolution)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="98" />
            <source>Largest hole width filled (m)</source>
            <translation>Largeur maximale des trous comblés (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="106" />
            <source>Sharpen blurred height steps</source>
            <translation>Rendre nets les sauts de hauteur flous</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="111" />
            <source>Edge-preserving smoothing of planar surfaces</source>
            <translation>Lissage des surfaces planes préservant les arêtes</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="117" />
            <source>Outlier window (cells, odd)</source>
            <translation>Fenêtre des valeurs aberrantes (cellules, impair)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="128" />
            <source>Supporting neighbours that keep a cell</source>
            <translation>Voisins d'appui qui conservent une cellule</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="138" />
            <source>Minimum confidence</source>
            <translation>Confiance minimale</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="149" />
            <source>Confident cells (confidence at least)</source>
            <translation>Cellules fiables (confiance au moins)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="160" />
            <source>Height step between surfaces (m)</source>
            <translation>Saut de hauteur entre surfaces (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="170" />
            <source>Smoothing radius (cells)</source>
            <translation>Rayon de lissage (cellules)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="181" />
            <source>Smoothing height tolerance (m; empty = 2.5 x resolution)</source>
            <translation>Tolérance en hauteur du lissage (m ; vide = 2,5 x la résolution)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="192" />
            <source>Ground filter cell size (m; empty = max(1 m, resolution))</source>
            <translation>Taille de cellule du filtre de sol (m ; vide = max(1 m, résolution))</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="203" />
            <source>Ground filter window radius (m)</source>
            <translation>Rayon de fenêtre du filtre de sol (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="213" />
            <source>Ground filter slope (rise/run)</source>
            <translation>Pente du filtre de sol (dénivelé/distance)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="224" />
            <source>Terrain model (DTM)</source>
            <translation>Modèle numérique de terrain (MNT)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="229" />
            <source>Normalised DSM (height above terrain)</source>
            <translation>MNS normalisé (hauteur au-dessus du terrain)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="232" />
            <source>Statistics (JSON)</source>
            <translation>Statistiques (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="233" />
            <source>Outliers removed (cells)</source>
            <translation>Valeurs aberrantes supprimées (cellules)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="234" />
            <source>Hole cells filled</source>
            <translation>Cellules de trous comblées</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="235" />
            <source>Holes left as nodata</source>
            <translation>Trous laissés en NoData</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="322" />
            <source>DTM</source>
            <translation>MNT</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="282" />
            <source>{} holes ({} cells, widest {:.1f} m) are wider than {} m and stay nodata</source>
            <translation>{} trous ({} cellules, le plus large {:.1f} m) dépassent {} m et restent en NoData</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/dsmfilter.py" line="310" />
            <source>Ground filter at {:.2f} m: {:.1f} % of the cells are ground</source>
            <translation>Filtre de sol à {:.2f} m : {:.1f} % des cellules sont du sol</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="90" />
            <source>Check environment</source>
            <translation>Vérifier l'environnement</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="99" />
            <source>Reports the versions of QGIS, GDAL, rasterio, numpy, numba, OpenCV and pyproj that TruOrtho runs with, and writes them to a JSON file. Fails if rasterio is linked to a different GDAL than QGIS. Also reports TruOrtho's cache folder (compiled kernels and image features; the environment variable TRUORTHO_CACHE_DIR moves it, default the per-user cache folder of the system) and its size; CLEAR_CACHE empties it.</source>
            <translation>Indique les versions de QGIS, GDAL, rasterio, numpy, numba, OpenCV et pyproj avec lesquelles TruOrtho fonctionne et les écrit dans un fichier JSON. Échoue si rasterio est lié à un autre GDAL que QGIS. Indique aussi le dossier de cache de TruOrtho (noyaux compilés et points caractéristiques des images ; la variable d'environnement TRUORTHO_CACHE_DIR le déplace, par défaut le dossier de cache de l'utilisateur du système) et sa taille ; CLEAR_CACHE le vide.</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="143" />
            <source>rasterio is linked to GDAL {} but QGIS uses GDAL {}: use Debian's python3-rasterio</source>
            <translation>rasterio est lié à GDAL {} mais QGIS utilise GDAL {} : utilisez le paquet python3-rasterio de Debian</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="113" />
            <source>Versions (JSON)</source>
            <translation>Versions (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="113" />
            <source>JSON files (*.json)</source>
            <translation>Fichiers JSON (*.json)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="119" />
            <source>Clear the cache (compiled kernels, image features)</source>
            <translation>Vider le cache (noyaux compilés, points caractéristiques des images)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="124" />
            <source>Versions as JSON text</source>
            <translation>Versions en texte JSON</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="131" />
            <source>Cache cleared: {:.1f} MB freed</source>
            <translation>Cache vidé : {:.1f} Mo libérés</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="140" />
            <source>Not importable: {}</source>
            <translation>Non importable : {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/environment.py" line="136" />
            <source>not available</source>
            <translation>non disponible</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="21" />
            <source>Export orientation</source>
            <translation>Exporter l'orientation</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="36" />
            <source>Format</source>
            <translation>Format</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="41" />
            <source>Output folder</source>
            <translation>Dossier de sortie</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="42" />
            <source>Files written</source>
            <translation>Fichiers écrits</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="37" />
            <source>COLMAP text model</source>
            <translation>Modèle texte COLMAP</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="37" />
            <source>Orthority OPK CSV + interior file</source>
            <translation>CSV OPK Orthority + fichier d'orientation interne</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/exportorientation.py" line="54" />
            <source>Wrote {}</source>
            <translation>{} écrit</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="26" />
            <source>Import GCP list</source>
            <translation>Importer une liste de points d'appui</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="44" />
            <source>GCP list (ODM gcp_list.txt)</source>
            <translation>Liste de points d'appui (gcp_list.txt d'ODM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="47" />
            <source>Check point names (comma-separated)</source>
            <translation>Noms des points de contrôle (séparés par des virgules)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="53" />
            <source>Default sigma XY [m]</source>
            <translation>Sigma XY par défaut [m]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="62" />
            <source>Default sigma Z [m]</source>
            <translation>Sigma Z par défaut [m]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="68" />
            <source>Reproject to CRS</source>
            <translation>Reprojeter dans le SCR</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="76" />
            <source>GCP image measurements</source>
            <translation>Mesures image des points d'appui</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="129" />
            <source>{} GCPs ({} check points), {} image measurements</source>
            <translation>{} points d'appui ({} points de contrôle), {} mesures image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importgcps.py" line="103" />
            <source>CHECK_POINTS: unknown GCP name(s) {}; the file has {}</source>
            <translation>CHECK_POINTS : nom(s) de point d'appui inconnu(s) {} ; le fichier contient {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="44" />
            <source>Import orientation</source>
            <translation>Importer une orientation</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="62" />
            <source>Orientation file (COLMAP, Orthority CSV, OpenSfM)</source>
            <translation>Fichier d'orientation (COLMAP, CSV Orthority, OpenSfM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="66" />
            <source>Interior parameter file (Orthority)</source>
            <translation>Fichier des paramètres internes (Orthority)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="71" />
            <source>CRS of the input (when the file has none)</source>
            <translation>SCR de l'entrée (si le fichier n'en indique pas)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="86" />
            <source>Footprint height</source>
            <translation>Hauteur des emprises</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="93" />
            <source>Orientation (JSON)</source>
            <translation>Orientation (JSON)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="99" />
            <source>Cameras</source>
            <translation>Caméras</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="107" />
            <source>Footprints</source>
            <translation>Emprises des images</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="133" />
            <source>The orientation has no CRS: it stays in its arbitrary (local) frame. Give CRS (or a georef.json) to georeference it.</source>
            <translation>L'orientation n'a pas de SCR : elle reste dans son repère arbitraire (local). Indiquez CRS (ou un georef.json) pour la géoréférencer.</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="149" />
            <source>OBSERVATIONS given without a GCPS layer</source>
            <translation>OBSERVATIONS fourni sans couche GCPS</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="123" />
            <source>Read {} images, {} cameras, {} sparse points</source>
            <translation>{} images, {} caméras, {} points épars lus</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="153" />
            <source>GCPs need a georeferenced orientation: give CRS for the input</source>
            <translation>Les points d'appui exigent une orientation géoréférencée : indiquez CRS pour l'entrée</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="130" />
            <source>{}: the orientation contains no images</source>
            <translation>{} : l'orientation ne contient aucune image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="159" />
            <source>{} GCPs with {} image measurements</source>
            <translation>{} points d'appui avec {} mesures image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/importorientation.py" line="194" />
            <source>Image {} does not see the plane at height {}</source>
            <translation>L'image {} ne voit pas le plan à la hauteur {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="27" />
            <source>Mesh from DSM or point cloud</source>
            <translation>Maillage à partir d'un MNS ou d'un nuage de points</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="61" />
            <source>DSM raster or point cloud (LAS/LAZ, EPT ept.json)</source>
            <translation>Raster MNS ou nuage de points (LAS/LAZ, EPT ept.json)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="66" />
            <source>Orthoimage for vertex colours</source>
            <translation>Orthoimage pour les couleurs des sommets</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="71" />
            <source>Largest vertical error (m; empty = half the DSM resolution)</source>
            <translation>Erreur verticale maximale (m ; vide = la moitié de la résolution du MNS)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="81" />
            <source>Smallest height step made a wall (m)</source>
            <translation>Plus petit saut de hauteur transformé en mur (m)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="90" />
            <source>Steepest slope kept as a surface (degrees)</source>
            <translation>Pente la plus forte conservée comme surface (degrés)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="101" />
            <source>Largest flat block (cells, power of two)</source>
            <translation>Plus grand bloc plat (cellules, puissance de deux)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="112" />
            <source>Point clouds: longest triangle edge (m; empty = automatic)</source>
            <translation>Nuages de points : arête de triangle la plus longue (m ; vide = automatique)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="123" />
            <source>Coordinates</source>
            <translation>Coordonnées</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="130" />
            <source>Mesh</source>
            <translation>Maillage</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="130" />
            <source>PLY mesh (*.ply);;Wavefront OBJ (*.obj)</source>
            <translation>Maillage PLY (*.ply);;Wavefront OBJ (*.obj)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="133" />
            <source>Vertices</source>
            <translation>Sommets</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="134" />
            <source>Faces</source>
            <translation>Faces</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="135" />
            <source>Wall faces</source>
            <translation>Faces de mur</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="62" />
            <source>DSM or point cloud (*.tif *.tiff *.las *.laz *.json);;All files (*.*)</source>
            <translation>MNS ou nuage de points (*.tif *.tiff *.las *.laz *.json);;Tous les fichiers (*.*)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="124" />
            <source>CRS (world coordinates)</source>
            <translation>SCR (coordonnées terrain)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="124" />
            <source>Local frame (world - offset, offset in the header)</source>
            <translation>Repère local (terrain - décalage, décalage dans l'en-tête)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="155" />
            <source>ORTHO is ignored for point clouds (their own colours are used)</source>
            <translation>ORTHO est ignoré pour les nuages de points (leurs propres couleurs sont utilisées)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="145" />
            <source>INPUT: file not found: {}</source>
            <translation>INPUT : fichier introuvable : {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="158" />
            <source>{} points in {} reference systems</source>
            <translation>{} points dans {} systèmes de référence</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/mesh.py" line="176" />
            <source>{} cells -&gt; {} vertices ({:.1%} of the cells), {} faces of which {} wall faces; step threshold {:.2f} m, vertical error &lt;= {:.3f} m</source>
            <translation>{} cellules -&gt; {} sommets ({:.1%} des cellules), {} faces dont {} faces de mur ; seuil de saut {:.2f} m, erreur verticale &lt;= {:.3f} m</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="60" />
            <source>Orient images (bundle block adjustment)</source>
            <translation>Orienter les images (compensation par faisceaux)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="93" />
            <source>Image files (instead of a folder)</source>
            <translation>Fichiers image (au lieu d'un dossier)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="99" />
            <source>Interior orientation file (optional)</source>
            <translation>Fichier d'orientation interne (facultatif)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="102" />
            <source>Output CRS</source>
            <translation>SCR de sortie</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="106" />
            <source>Working resolution (max image side, px)</source>
            <translation>Résolution de travail (plus grand côté de l'image, px)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="116" />
            <source>Features per image</source>
            <translation>Points caractéristiques par image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="125" />
            <source>Self-calibration</source>
            <translation>Autocalibration</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="137" />
            <source>Report (HTML)</source>
            <translation>Rapport (HTML)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="138" />
            <source>HTML files (*.html)</source>
            <translation>Fichiers HTML (*.html)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="154" />
            <source>Tie points</source>
            <translation>Points de liaison</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="160" />
            <source>GCP and check point residuals</source>
            <translation>Résidus des points d'appui et de contrôle</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="173" />
            <source>Give either IMAGES (a folder) or IMAGE_FILES, not both</source>
            <translation>Indiquez soit IMAGES (un dossier), soit IMAGE_FILES, pas les deux</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="183" />
            <source>IMAGES: give an image folder or a list of image files</source>
            <translation>IMAGES : indiquez un dossier d'images ou une liste de fichiers image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="225" />
            <source>Registered {} of {} images; sigma0 {:.3f} px</source>
            <translation>{} images sur {} orientées ; sigma0 {:.3f} px</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="198" />
            <source>{} control and {} check points</source>
            <translation>{} points d'appui et {} points de contrôle</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/orientimages.py" line="176" />
            <source>IMAGES: {} is not a folder</source>
            <translation>IMAGES : {} n'est pas un dossier</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="38" />
            <source>Dense matching (OSGM)</source>
            <translation>Appariement dense (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="307" />
            <source>DSM (OSGM)</source>
            <translation>MNS (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="86" />
            <source>Extent (default: the area seen by the images)</source>
            <translation>Emprise (par défaut : la zone vue par les images)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="92" />
            <source>Resolution (m; empty or 0 = median ground sample distance)</source>
            <translation>Résolution (m ; vide ou 0 = taille médiane du pixel au sol)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="102" />
            <source>Height step of the search (m; empty or 0 = the resolution)</source>
            <translation>Pas de hauteur de la recherche (m ; vide ou 0 = la résolution)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="112" />
            <source>Lowest height searched (m; empty = automatic)</source>
            <translation>Hauteur minimale recherchée (m ; vide = automatique)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="121" />
            <source>Highest height searched (m; empty = automatic)</source>
            <translation>Hauteur maximale recherchée (m ; vide = automatique)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="129" />
            <source>Coarse surface bounding the search per cell (DSM/DTM)</source>
            <translation>Surface grossière bornant la recherche par cellule (MNS/MNT)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="135" />
            <source>Aggregation paths</source>
            <translation>Chemins d'agrégation</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="143" />
            <source>Oblique images</source>
            <translation>Images obliques</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="151" />
            <source>Penalty P1, one height step (cost units; empty = default)</source>
            <translation>Pénalité P1, un pas de hauteur (unités de coût ; vide = par défaut)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="162" />
            <source>Penalty P2, larger height jumps (cost units; empty = default)</source>
            <translation>Pénalité P2, sauts de hauteur plus grands (unités de coût ; vide = par défaut)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="173" />
            <source>Images per tile (at most)</source>
            <translation>Images par tuile (au plus)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="183" />
            <source>Tile size (cells)</source>
            <translation>Taille des tuiles (cellules)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="195" />
            <source>Confidence [0, 1]</source>
            <translation>Confiance [0, 1]</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="200" />
            <source>Orthoimage (matching colours)</source>
            <translation>Orthoimage (couleurs de l'appariement)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="206" />
            <source>Point cloud</source>
            <translation>Nuage de points</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="231" />
            <source>EXTENT: the extent is empty</source>
            <translation>EXTENT : l'emprise est vide</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="310" />
            <source>Confidence (OSGM)</source>
            <translation>Confiance (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="313" />
            <source>Orthoimage (OSGM)</source>
            <translation>Orthoimage (OSGM)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="144" />
            <source>none: one nadir reference system</source>
            <translation>none : un seul système de référence au nadir</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="144" />
            <source>auto: extra systems for obliques</source>
            <translation>auto : systèmes supplémentaires pour les obliques</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="244" />
            <source>ORIENTATION: the file {!r} does not exist</source>
            <translation>ORIENTATION : le fichier {!r} n'existe pas</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="256" />
            <source>Z_MIN ({}) must be below Z_MAX ({})</source>
            <translation>Z_MIN ({}) doit être inférieur à Z_MAX ({})</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="272" />
            <source>POINT_CLOUD: expected a .las or .laz file, got {!r}</source>
            <translation>POINT_CLOUD : fichier .las ou .laz attendu, reçu {!r}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="251" />
            <source>{}: must be positive (or empty), got {}</source>
            <translation>{} : doit être positif (ou vide), reçu {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/osgm.py" line="262" />
            <source>Z_SURFACE: expected a raster file (GeoTIFF), got {!r}</source>
            <translation>Z_SURFACE : fichier raster (GeoTIFF) attendu, reçu {!r}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="29" />
            <source>Photos to true orthophoto (whole pipeline)</source>
            <translation>Des photos à l'orthophoto vraie (chaîne complète)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="103" />
            <source>DSM (filtered)</source>
            <translation>MNS (filtré)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="106" />
            <source>True orthophoto</source>
            <translation>Orthophoto vraie</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="107" />
            <source>Occlusion mask</source>
            <translation>Masque d'occultation</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="108" />
            <source>Seamlines</source>
            <translation>Lignes de raccord</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="83" />
            <source>Resolution of the DSM and the true orthophoto (m, 0 = ground sample distance)</source>
            <translation>Résolution du MNS et de l'orthophoto vraie (m, 0 = taille du pixel au sol)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="92" />
            <source>Reuse an existing orientation.json in the output folder</source>
            <translation>Réutiliser un orientation.json existant dans le dossier de sortie</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="123" />
            <source>IMAGES: give the folder of the photos</source>
            <translation>IMAGES : indiquez le dossier des photos</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="139" />
            <source>OUTPUT_FOLDER: give a folder for the products</source>
            <translation>OUTPUT_FOLDER : indiquez un dossier pour les produits</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="149" />
            <source>RESOLUTION: expected a positive number of metres or 0</source>
            <translation>RESOLUTION : nombre positif de mètres ou 0 attendu</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="189" />
            <source>DSM (TruOrtho)</source>
            <translation>MNS (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="190" />
            <source>True orthophoto (TruOrtho)</source>
            <translation>Orthophoto vraie (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="191" />
            <source>Occlusion (TruOrtho)</source>
            <translation>Occultation (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="192" />
            <source>Seamlines (TruOrtho)</source>
            <translation>Lignes de raccord (TruOrtho)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="173" />
            <source>Tiles ran on: {}</source>
            <translation>Tuiles calculées sur : {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pipeline.py" line="172" />
            <source>{}: {:.1f} s, peak {:.0f} MB; {}</source>
            <translation>{} : {:.1f} s, pic {:.0f} Mo ; {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="39" />
            <source>DSM to point cloud (LAS/LAZ + EPT)</source>
            <translation>MNS en nuage de points (LAS/LAZ + EPT)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="95" />
            <source>Merge point clouds (reference systems)</source>
            <translation>Fusionner des nuages de points (systèmes de référence)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="27" />
            <source>LAZ (compressed) (*.laz);;LAS (*.las)</source>
            <translation>LAZ (compressé) (*.laz);;LAS (*.las)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="51" />
            <source>DSM</source>
            <translation>MNS</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="53" />
            <source>Orthoimage for point colours</source>
            <translation>Orthoimage pour les couleurs des points</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="62" />
            <source>EPT dataset folder (opens in QGIS without PDAL)</source>
            <translation>Dossier du jeu de données EPT (s'ouvre dans QGIS sans PDAL)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="67" />
            <source>EPT ept.json</source>
            <translation>EPT ept.json</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="68" />
            <source>Points</source>
            <translation>Points</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="110" />
            <source>Point clouds (LAS/LAZ)</source>
            <translation>Nuages de points (LAS/LAZ)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="116" />
            <source>Thin duplicates on a voxel grid (m; empty = keep all)</source>
            <translation>Éclaircir les doublons sur une grille de voxels (m ; vide = tout conserver)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="123" />
            <source>Merged point cloud</source>
            <translation>Nuage de points fusionné</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="87" />
            <source>{} points written to {}</source>
            <translation>{} points écrits dans {}</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="150" />
            <source>{} points from {} files ({} after thinning)</source>
            <translation>{} points issus de {} fichiers ({} après éclaircissement)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/pointcloud.py" line="89" />
            <source>EPT dataset: {} (add it as a point cloud layer)</source>
            <translation>Jeu de données EPT : {} (à ajouter comme couche nuage de points)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="93" />
            <source>Surface: DSM raster or mesh</source>
            <translation>Surface : raster MNS ou maillage</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="98" />
            <source>Extent (default: the surface's)</source>
            <translation>Emprise (par défaut : celle de la surface)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="103" />
            <source>Resolution (CRS units; 0 = the surface's cell size)</source>
            <translation>Résolution (unités du SCR ; 0 = taille de cellule de la surface)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="110" />
            <source>Output CRS (default: the orientation's)</source>
            <translation>SCR de sortie (par défaut : celui de l'orientation)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="114" />
            <source>Colour correction</source>
            <translation>Correction colorimétrique</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="120" />
            <source>Remove vignetting (with the colour correction)</source>
            <translation>Supprimer le vignettage (avec la correction colorimétrique)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="129" />
            <source>Maximum off-nadir viewing angle (degrees)</source>
            <translation>Angle de visée maximal par rapport au nadir (degrés)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="139" />
            <source>Blend width across seamlines (cells)</source>
            <translation>Largeur du fondu aux lignes de raccord (cellules)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="160" />
            <source>Compression of the orthophoto</source>
            <translation>Compression de l'orthophoto</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="173" />
            <source>JPEG quality</source>
            <translation>Qualité JPEG</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="185" />
            <source>Source image index</source>
            <translation>Index de l'image source</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="196" />
            <source>Seamlines (source image regions)</source>
            <translation>Lignes de raccord (zones des images sources)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="211" />
            <source>SURFACE: give a DSM raster or a mesh file</source>
            <translation>SURFACE : indiquez un raster MNS ou un fichier de maillage</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="94" />
            <source>Surfaces (*.tif *.tiff *.vrt *.ply *.obj);;All files (*.*)</source>
            <translation>Surfaces (*.tif *.tiff *.vrt *.ply *.obj);;Tous les fichiers (*.*)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="247" />
            <source>{} x {} cells, {} images used, coverage {:.2%}, {} cells seen by no image</source>
            <translation>{} x {} cellules, {} images utilisées, couverture {:.2%}, {} cellules vues par aucune image</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="162" />
            <source>DEFLATE (lossless, read by every GIS)</source>
            <translation>DEFLATE (sans perte, lu par tous les SIG)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="163" />
            <source>ZSTD (lossless, fastest to write, larger)</source>
            <translation>ZSTD (sans perte, écriture la plus rapide, plus volumineux)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="164" />
            <source>LZW (lossless)</source>
            <translation>LZW (sans perte)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="165" />
            <source>JPEG (lossy, 8-bit RGB images only; alpha becomes a mask)</source>
            <translation>JPEG (avec perte, images RVB 8 bits seulement ; l'alpha devient un masque)</translation>
        </message>
        <message>
            <location filename="../processing/algorithms/trueortho.py" line="254" />
            <source>colour correction ({}): disagreement between photos, median {:.2f} -&gt; {:.2f}</source>
            <translation>correction colorimétrique ({}) : écart entre les photos, médiane {:.2f} -&gt; {:.2f}</translation>
        </message>
        <message>
            <location filename="../processing/feedback.py" line="86" />
            <source>Cancelled by the user</source>
            <translation>Annulé par l'utilisateur</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="12" />
            <source>JPEG photos smear colour over a few pixels across roof outlines, where roof and ground are about as bright (the brightness cannot restore it). Within 3 cells of the surface's height steps, a cell's colour (not its brightness) can be taken from the cells of its own surface farther from the step. checked (the default): only where the cell's colour is already nearer its own surface's than the other side's, so that a DSM from image matching, whose outlines may be a cell or two off, does not get roof colours painted on the ground. surface: every such cell, for a surface whose outlines are exact (a LiDAR DSM, a building model). off: the mosaic's colours as sampled. RGB images only.</source>
            <translation>Les photos JPEG étalent la couleur sur quelques pixels à travers les bords de toit, là où le toit et le sol sont à peu près aussi clairs (la luminosité ne peut pas la restaurer). À moins de 3 cellules des ruptures de hauteur de la surface, la couleur d'une cellule (pas sa luminosité) peut être prise des cellules de sa propre surface plus éloignées de la rupture. checked (par défaut) : seulement là où la couleur de la cellule est déjà plus proche de celle de sa propre surface que de celle de l'autre côté, pour qu'un MNS issu de la corrélation d'images, dont les contours peuvent être décalés d'une ou deux cellules, ne reçoive pas la couleur des toits peinte sur le sol. surface : chaque cellule de ce type, pour une surface aux contours exacts (un MNS LiDAR, un modèle de bâtiments). off : les couleurs de la mosaïque telles qu'échantillonnées. Images RVB seulement.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="23" />
            <source>Address of the Dask scheduler for EXECUTOR = scheduler: tls://host:8786, or the path of a scheduler file; empty = the environment variable TRUORTHO_DASK_SCHEDULER. Security: a Dask scheduler executes any code its clients send, so it must never be reachable unauthenticated. Use TLS with certificates for a remote scheduler (configured in Dask's configuration, distributed.comm.tls), or an SSH tunnel to 127.0.0.1; a plain tcp:// address that is not on this computer is refused.</source>
            <translation>Adresse du planificateur Dask pour EXECUTOR = scheduler : tls://hôte:8786, ou le chemin d'un fichier de planificateur ; vide = la variable d'environnement TRUORTHO_DASK_SCHEDULER. Sécurité : un planificateur Dask exécute tout code que ses clients lui envoient, il ne doit donc jamais être joignable sans authentification. Utilisez TLS avec des certificats pour un planificateur distant (configuré dans la configuration de Dask, distributed.comm.tls), ou un tunnel SSH vers 127.0.0.1 ; une adresse tcp:// simple qui n'est pas sur cet ordinateur est refusée.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="35" />
            <source>Imports the orientation of an image block (interior and exterior orientation of every image, sparse points) from COLMAP, Orthority or OpenSfM/ODM files into TruOrtho's orientation JSON, and writes a layer of projection centres and a layer of image footprints. Conventions (camera axes, rotations, pixel origin) are converted at import; see docs/FORMATS.md.</source>
            <translation>Importe l'orientation d'un bloc d'images (orientation interne et externe de chaque image, points épars) depuis des fichiers COLMAP, Orthority ou OpenSfM/ODM dans le JSON d'orientation de TruOrtho, et écrit une couche des centres de projection et une couche des emprises des images. Les conventions (axes de la caméra, rotations, origine des pixels) sont converties à l'import ; voir docs/FORMATS.md.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="43" />
            <source>COLMAP text model (cameras.txt, images.txt or points3D.txt; the folder is used, with an optional georef.json {"crs": ..., "offset": [E, N, H]}), Orthority exterior CSV (filename, x, y, z, omega, phi, kappa[, camera]; degrees), OpenSfM/ODM reconstruction.json, or a TruOrtho orientation JSON.</source>
            <translation>Modèle texte COLMAP (cameras.txt, images.txt ou points3D.txt ; le dossier est utilisé, avec un georef.json facultatif {"crs": ..., "offset": [E, N, H]}), CSV d'orientation externe Orthority (filename, x, y, z, omega, phi, kappa[, camera] ; degrés), reconstruction.json OpenSfM/ODM, ou un JSON d'orientation TruOrtho.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="48" />
            <source>Orthority interior parameter file (YAML or JSON); required with a CSV input.</source>
            <translation>Fichier des paramètres internes Orthority (YAML ou JSON) ; obligatoire avec une entrée CSV.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="49" />
            <source>CRS of the input coordinates when the file does not state it (CSV without .prj, COLMAP without georef.json); target CRS for OpenSfM's topocentric frame.</source>
            <translation>SCR des coordonnées d'entrée lorsque le fichier ne l'indique pas (CSV sans .prj, COLMAP sans georef.json) ; SCR cible pour le repère topocentrique d'OpenSfM.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="51" />
            <source>Folder holding the images; every image of the block must be present there.</source>
            <translation>Dossier contenant les images ; chaque image du bloc doit s'y trouver.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="52" />
            <source>Optional ground control: point layer with 'name', 'role' (gcp|check), PointZ or a 'z' field, optional 'sigma_xy'/'sigma_z' in metres. Reprojected to the orientation's CRS.</source>
            <translation>Points d'appui facultatifs : couche de points avec 'name', 'role' (gcp|check), PointZ ou un champ 'z', et facultativement 'sigma_xy'/'sigma_z' en mètres. Reprojetés dans le SCR de l'orientation.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="54" />
            <source>Image measurements of the GCPs: table with 'gcp', 'image', 'x', 'y' in pixels ((0, 0) = centre of the top-left pixel).</source>
            <translation>Mesures image des points d'appui : table avec 'gcp', 'image', 'x', 'y' en pixels ((0, 0) = centre du pixel en haut à gauche).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="56" />
            <source>Height (in the CRS) of the plane the footprints are drawn on; default the median height of the sparse points, or of the GCPs, or 0.</source>
            <translation>Hauteur (dans le SCR) du plan sur lequel les emprises sont tracées ; par défaut la hauteur médiane des points épars, sinon des points d'appui, sinon 0.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="58" />
            <source>The orientation JSON (TruOrtho format, version 1).</source>
            <translation>Le JSON d'orientation (format TruOrtho, version 1).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="59" />
            <source>Optional: projection centres as PointZ with name, camera, x, y, z, omega, phi, kappa (degrees); skipped when not given.</source>
            <translation>Facultatif : centres de projection en PointZ avec name, camera, x, y, z, omega, phi, kappa (degrés) ; omis s'il n'est pas donné.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="61" />
            <source>Image footprints on the horizontal plane at FOOTPRINT_HEIGHT.</source>
            <translation>Emprises des images sur le plan horizontal à la hauteur FOOTPRINT_HEIGHT.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="66" />
            <source>Exports a TruOrtho orientation JSON to a COLMAP text model (cameras.txt, images.txt, points3D.txt and georef.json) or to Orthority frame-camera files (exterior.csv with a .prj sidecar and interior.yaml).</source>
            <translation>Exporte un JSON d'orientation TruOrtho vers un modèle texte COLMAP (cameras.txt, images.txt, points3D.txt et georef.json) ou vers des fichiers Orthority de caméra à cadre (exterior.csv avec un fichier annexe .prj et interior.yaml).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="71" />
            <source>A TruOrtho orientation JSON.</source>
            <translation>Un JSON d'orientation TruOrtho.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="72" />
            <source>colmap or opk (Orthority CSV + interior file).</source>
            <translation>colmap ou opk (CSV Orthority + fichier d'orientation interne).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="73" />
            <source>Folder the files are written to (created if needed).</source>
            <translation>Dossier dans lequel les fichiers sont écrits (créé si nécessaire).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="78" />
            <source>Reads an ODM/OpenSfM gcp_list.txt (first line EPSG code, PROJ string or 'WGS84 UTM nnX'; then 'X Y Z px py image [name]') into a GCP point layer and an observation table, the two inputs ground control takes everywhere in TruOrtho.</source>
            <translation>Lit un fichier gcp_list.txt d'ODM/OpenSfM (première ligne : code EPSG, chaîne PROJ ou 'WGS84 UTM nnX' ; puis 'X Y Z px py image [name]') dans une couche de points d'appui et une table d'observations, les deux entrées qu'utilisent les points d'appui partout dans TruOrtho.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="83" />
            <source>The gcp_list.txt file.</source>
            <translation>Le fichier gcp_list.txt.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="84" />
            <source>Comma-separated GCP names to mark as check points (role 'check').</source>
            <translation>Noms de points d'appui, séparés par des virgules, à marquer comme points de contrôle (rôle 'check').</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="85" />
            <source>Default planimetric standard deviation of the GCP coordinates, metres.</source>
            <translation>Écart type planimétrique par défaut des coordonnées des points d'appui, en mètres.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="86" />
            <source>Default height standard deviation of the GCP coordinates, metres.</source>
            <translation>Écart type altimétrique par défaut des coordonnées des points d'appui, en mètres.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="87" />
            <source>Optional CRS to reproject the GCPs to (default: the file's CRS).</source>
            <translation>SCR facultatif dans lequel reprojeter les points d'appui (par défaut : le SCR du fichier).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="88" />
            <source>GCP point layer (PointZ): name, role, z, sigma_xy, sigma_z.</source>
            <translation>Couche des points d'appui (PointZ) : name, role, z, sigma_xy, sigma_z.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="89" />
            <source>Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the top-left pixel, as in gcp_list.txt).</source>
            <translation>Table d'observations : gcp, image, x, y (pixels, (0, 0) = centre du pixel en haut à gauche, comme dans gcp_list.txt).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="95" />
            <source>Finds ground targets in every photo of a folder and writes an observation table with a score per measurement. ArUco markers are found anywhere; the GCP is the marker's centre (intersection of the diagonals of its outer corners), refined by least-squares matching of the ideal marker. Circular and checkerboard (X) targets are searched near the positions an orientation predicts for the GCPs, then refined the same way. Measurements with a low score are kept and flagged, never dropped.</source>
            <translation>Trouve les cibles au sol dans chaque photo d'un dossier et écrit une table d'observations avec un score par mesure. Les marqueurs ArUco sont trouvés partout ; le point d'appui est le centre du marqueur (intersection des diagonales de ses coins extérieurs), affiné par corrélation par moindres carrés du marqueur idéal. Les cibles circulaires et en damier (X) sont cherchées près des positions qu'une orientation prédit pour les points d'appui, puis affinées de la même manière. Les mesures de faible score sont conservées et signalées, jamais supprimées.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="103" />
            <source>Folder of the photos (jpg, png, tif, jp2, bmp).</source>
            <translation>Dossier des photos (jpg, png, tif, jp2, bmp).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="104" />
            <source>ArUco markers, circular targets (a dark disc on a light ground or the reverse) or checkerboard targets (two dark and two light quadrants).</source>
            <translation>Marqueurs ArUco, cibles circulaires (un disque sombre sur fond clair ou l'inverse) ou cibles en damier (deux quadrants sombres et deux clairs).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="106" />
            <source>The ArUco dictionary the markers were printed from.</source>
            <translation>Le dictionnaire ArUco dont les marqueurs ont été imprimés.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="107" />
            <source>ArUco only: marker ID to GCP name, e.g. 0=GCP1,1=GCP2. With a GCP layer, every name must be in it.</source>
            <translation>ArUco seulement : ID du marqueur vers nom du point d'appui, p. ex. 0=GCP1,1=GCP2. Avec une couche de points d'appui, chaque nom doit y figurer.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="109" />
            <source>Circular and checkerboard targets: the orientation (TruOrtho JSON) of the photos, used to predict where each GCP appears.</source>
            <translation>Cibles circulaires et en damier : l'orientation (JSON TruOrtho) des photos, qui sert à prédire où apparaît chaque point d'appui.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="111" />
            <source>Point layer of the GCPs ('name' field; PointZ or a 'z' field) whose positions are predicted; for ArUco it only checks the names of MARKER_IDS.</source>
            <translation>Couche de points des points d'appui (champ 'name' ; PointZ ou un champ 'z') dont les positions sont prédites ; pour ArUco elle sert seulement à vérifier les noms de MARKER_IDS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="113" />
            <source>Circular and checkerboard targets are searched this many pixels around their predicted positions.</source>
            <translation>Les cibles circulaires et en damier sont cherchées à cette distance (pixels) autour de leurs positions prédites.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="115" />
            <source>Measurements scoring lower (normalised cross-correlation of the ideal target with the photo, 0 to 1) are flagged 'low score'.</source>
            <translation>Les mesures de score inférieur (corrélation croisée normalisée de la cible idéale avec la photo, de 0 à 1) sont signalées 'low score'.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="117" />
            <source>Refine every centre by least-squares matching of the ideal target (gives the standard deviations).</source>
            <translation>Affiner chaque centre par corrélation par moindres carrés de la cible idéale (donne les écarts-types).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="119" />
            <source>Observation table: gcp, image, x, y (pixels, (0, 0) = centre of the top-left pixel), score, sigma_x, sigma_y (pixels, empty when the refinement failed) and flag (ok, low score, refinement failed: reason).</source>
            <translation>Table d'observations : gcp, image, x, y (pixels, (0, 0) = centre du pixel en haut à gauche), score, sigma_x, sigma_y (pixels, vides si l'affinage a échoué) et flag (ok, low score, refinement failed : raison).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="126" />
            <source>Orients a block of overlapping photos: SIFT features at a working resolution, pair selection (exhaustive for small blocks, EXIF GNSS footprints, or a low-resolution retrieval pass), robust two-view geometry, tie-point tracks decimated on a grid by multiplicity, incremental reconstruction and a bundle block adjustment written for TruOrtho (collinearity equations with Brown distortion, Levenberg-Marquardt with the Schur complement, Huber loss, self-calibration). Ground control fixes the datum (7-parameter similarity, then weighted GCP observations); check points never enter the adjustment and are reported with per-axis RMSE. Without GCPs, EXIF GNSS positions serve as weighted priors; without either the block stays in an arbitrary frame.</source>
            <translation>Oriente un bloc de photos qui se recouvrent : points caractéristiques SIFT à une résolution de travail, sélection des paires (exhaustive pour les petits blocs, emprises issues du GNSS EXIF, ou une passe de recherche à basse résolution), géométrie robuste à deux vues, pistes de points de liaison éclaircies sur une grille selon leur multiplicité, reconstruction incrémentale et une compensation par faisceaux écrite pour TruOrtho (équations de colinéarité avec distorsion de Brown, Levenberg-Marquardt avec le complément de Schur, perte de Huber, autocalibration). Les points d'appui fixent le datum (similitude à 7 paramètres, puis observations pondérées des points d'appui) ; les points de contrôle n'entrent jamais dans la compensation et sont rapportés avec l'EMQ par axe. Sans points d'appui, les positions GNSS EXIF servent d'a priori pondérés ; sans l'un ni l'autre, le bloc reste dans un repère arbitraire.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="136" />
            <source>Folder of the images (non-image files are skipped with a warning in the report).</source>
            <translation>Dossier des images (les fichiers qui ne sont pas des images sont ignorés avec un avertissement dans le rapport).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="137" />
            <source>The image files, instead of a folder.</source>
            <translation>Les fichiers image, au lieu d'un dossier.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="138" />
            <source>Interior orientation: an Orthority interior file (YAML/JSON) or a text file with the 3x3 matrix K, taken as a calibration and held fixed. Without it: EXIF focal length and sensor size, else f = 1.2 x max(w, h), refined by self-calibration.</source>
            <translation>Orientation interne : un fichier interne Orthority (YAML/JSON) ou un fichier texte avec la matrice 3x3 K, pris comme étalonnage et maintenu fixe. Sans lui : focale et taille du capteur EXIF, sinon f = 1,2 x max(w, h), affinés par autocalibration.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="141" />
            <source>Ground control and check points: point layer with 'name', 'role' (gcp|check), PointZ or 'z', optional 'sigma_xy'/'sigma_z' (metres). Reprojected to CRS.</source>
            <translation>Points d'appui et de contrôle : couche de points avec 'name', 'role' (gcp|check), PointZ ou 'z', facultativement 'sigma_xy'/'sigma_z' (mètres). Reprojetés dans CRS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="143" />
            <source>Image measurements of the GCPs: table with 'gcp', 'image' (file name), 'x', 'y' (pixels, (0, 0) = centre of the top-left pixel).</source>
            <translation>Mesures image des points d'appui : table avec 'gcp', 'image' (nom de fichier), 'x', 'y' (pixels, (0, 0) = centre du pixel en haut à gauche).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="145" />
            <source>CRS of the output (default: the GCP layer's, else the UTM zone of the EXIF GNSS positions).</source>
            <translation>SCR de la sortie (par défaut : celui de la couche des points d'appui, sinon la zone UTM des positions GNSS EXIF).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="147" />
            <source>Larger image side at which features are detected, pixels.</source>
            <translation>Plus grand côté de l'image auquel les points caractéristiques sont détectés, en pixels.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="148" />
            <source>Features kept per image.</source>
            <translation>Points caractéristiques conservés par image.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="149" />
            <source>Estimate f, cx, cy, k1, k2, p1, p2 in the adjustment when no CAMERA file is given (else hold the prior interior orientation).</source>
            <translation>Estimer f, cx, cy, k1, k2, p1, p2 dans la compensation lorsqu'aucun fichier CAMERA n'est fourni (sinon maintenir l'orientation interne a priori).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="151" />
            <source>The adjusted orientation (TruOrtho JSON).</source>
            <translation>L'orientation compensée (JSON TruOrtho).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="152" />
            <source>HTML report (and a JSON file of the same name): sigma0, image RMS, per-image residuals, GCP and check point tables, residual vector plots, tie-point multiplicity histogram, block overview. Optional: by default written beside ORIENTATION as name_report.html.</source>
            <translation>Rapport HTML (et un fichier JSON du même nom) : sigma0, RMS image, résidus par image, tableaux des points d'appui et de contrôle, graphiques des vecteurs résidus, histogramme de multiplicité des points de liaison, vue d'ensemble du bloc. Facultatif : par défaut écrit à côté d'ORIENTATION sous le nom nom_report.html.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="156" />
            <source>Optional: projection centres (PointZ) with omega, phi, kappa; skipped when not given.</source>
            <translation>Facultatif : centres de projection (PointZ) avec omega, phi, kappa ; omis s'il n'est pas donné.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="158" />
            <source>Tie points (PointZ) with multiplicity, mean reprojection error and colour.</source>
            <translation>Points de liaison (PointZ) avec multiplicité, erreur de reprojection moyenne et couleur.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="159" />
            <source>GCPs and check points with dX, dY, dZ (adjusted or triangulated minus surveyed).</source>
            <translation>Points d'appui et de contrôle avec dX, dY, dZ (compensés ou triangulés moins levés).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="165" />
            <source>The whole chain from photos to a true orthophoto in one run: image orientation with the ground control (bundle block adjustment), dense matching in object space (OSGM), DSM filtering, a mesh, and the true orthophoto with its occlusion mask and seamlines, plus one HTML report (block overview, sigma0, GCP and check point tables, residual plot, DSM hillshade, true-orthophoto preview, time and memory per stage). The products are written to OUTPUT_FOLDER with fixed names: orientation.json, report.html, dsm.tif, pointcloud.laz, mesh.ply, trueortho.tif, occlusion.tif, seamlines.gpkg (and the raw DSM, confidence and orthoimage of the matching).</source>
            <translation>Toute la chaîne des photos à l'orthophoto vraie en une seule exécution : orientation des images avec les points d'appui (compensation par faisceaux), appariement dense dans l'espace objet (OSGM), filtrage du MNS, un maillage, et l'orthophoto vraie avec son masque d'occultation et ses lignes de raccord, plus un rapport HTML (vue d'ensemble du bloc, sigma0, tables des points d'appui et de contrôle, graphique des résidus, ombrage du MNS, aperçu de l'orthophoto vraie, temps et mémoire par étape). Les produits sont écrits dans OUTPUT_FOLDER sous des noms fixes : orientation.json, report.html, dsm.tif, pointcloud.laz, mesh.ply, trueortho.tif, occlusion.tif, seamlines.gpkg (ainsi que le MNS brut, la confiance et l'orthoimage de l'appariement).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="175" />
            <source>Folder of the photos (JPEG, TIFF, PNG...); other files are skipped.</source>
            <translation>Dossier des photos (JPEG, TIFF, PNG...) ; les autres fichiers sont ignorés.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="176" />
            <source>Optional interior orientation (Orthority YAML/JSON or a 3x3 K text file), held fixed; otherwise EXIF priors refined by self-calibration.</source>
            <translation>Orientation interne facultative (YAML/JSON Orthority ou fichier texte de la matrice 3x3 K), maintenue fixe ; sinon des valeurs a priori EXIF affinées par autocalibration.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="178" />
            <source>Optional point layer of ground control and check points (fields name, role gcp|check, optional z, sigma_xy, sigma_z), as for Orient images. Needed for a georeferenced product unless the photos carry EXIF GNSS positions.</source>
            <translation>Couche de points facultative des points d'appui et de contrôle (champs name, role gcp|check, facultativement z, sigma_xy, sigma_z), comme pour Orienter les images. Nécessaire pour un produit géoréférencé, sauf si les photos portent des positions GNSS EXIF.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="181" />
            <source>Table of the GCP image measurements (gcp, image, x, y), given with GCPS.</source>
            <translation>Table des mesures image des points d'appui (gcp, image, x, y), fournie avec GCPS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="182" />
            <source>CRS of the products; default the GCP layer's CRS.</source>
            <translation>SCR des produits ; par défaut le SCR de la couche des points d'appui.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="183" />
            <source>Cell size of the DSM and the true orthophoto in metres; 0 = the median ground sample distance of the near-nadir images.</source>
            <translation>Taille de cellule du MNS et de l'orthophoto vraie en mètres ; 0 = taille médiane du pixel au sol des images proches du nadir.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="185" />
            <source>Skip the orientation when OUTPUT_FOLDER already holds orientation.json (e.g. to rerun matching and the orthophoto with another resolution).</source>
            <translation>Sauter l'orientation lorsque OUTPUT_FOLDER contient déjà orientation.json (par ex. pour relancer l'appariement et l'orthophoto avec une autre résolution).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="187" />
            <source>Most cameras store JPEG colour at half the resolution of the brightness (4:2:0 or 4:2:2, read from each file's header), so colours smear across building outlines. When on, the colour edges of such images are restored from the brightness before they are sampled at full resolution. Other images are not changed.</source>
            <translation>La plupart des appareils enregistrent la couleur des JPEG à la moitié de la résolution de la luminance (4:2:0 ou 4:2:2, lu dans l'en-tête de chaque fichier), si bien que les couleurs débordent des contours des bâtiments. Activé, les contours de couleur de ces images sont restaurés à partir de la luminance avant leur échantillonnage à pleine résolution. Les autres images ne sont pas modifiées.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="192" />
            <source>Where the tiles of dense matching, DSM filtering and the true orthophoto are computed, by one executor for the three stages (a local cluster starts once); the products are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the photos and OUTPUT_FOLDER at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The orientation, the mesh and the report are computed in QGIS's process. The address is checked before the orientation starts; the scheduler is first contacted by dense matching.</source>
            <translation>Où les tuiles de l'appariement dense, du filtrage du MNS et de l'orthophoto vraie sont calculées, par un seul exécuteur pour les trois étapes (une grappe locale ne démarre qu'une fois) ; les produits sont identiques quel que soit le choix. inprocess : dans le processus de QGIS, une tuile après l'autre sur tous les cœurs (par défaut). local : une grappe Dask de processus de travail sur cet ordinateur, à l'écoute sur 127.0.0.1 seulement (un processus par cœur, chacun avec une limite de mémoire). scheduler : une grappe Dask existante, donnée par SCHEDULER_ADDRESS ; ses processus de travail doivent lire les photos et OUTPUT_FOLDER aux mêmes chemins (stockage partagé) et avoir TruOrtho installé. Les tuiles d'un processus de travail qui meurt sont recalculées par les autres. L'orientation, le maillage et le rapport sont calculés dans le processus de QGIS. L'adresse est vérifiée avant le début de l'orientation ; l'ordonnanceur est contacté pour la première fois par l'appariement dense.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="203" />
            <source>Folder of the products (created when missing; existing products are replaced). It holds only products: orientation.json (adjusted orientation), report.html and report.json (the quality report and its data), dsm_raw.tif (DSM as matched, before filtering), confidence.tif (matching confidence 0 to 1), orthoimage.tif (colour of each DSM cell from the matching, not a true orthophoto), dsm.tif (filtered DSM), pointcloud.laz, mesh.ply, trueortho.tif, source_index.tif (which photo each true-orthophoto cell comes from), occlusion.tif and seamlines.gpkg. Caches (compiled kernels, image features) are kept in the per-user cache folder (environment variable TRUORTHO_CACHE_DIR; truortho:environment shows and clears it).</source>
            <translation>Dossier des produits (créé s'il manque ; les produits existants sont remplacés). Il ne contient que des produits : orientation.json (orientation compensée), report.html et report.json (le rapport de qualité et ses données), dsm_raw.tif (MNS tel qu'apparié, avant filtrage), confidence.tif (confiance de l'appariement de 0 à 1), orthoimage.tif (couleur de chaque cellule du MNS issue de l'appariement, pas une vraie orthophoto), dsm.tif (MNS filtré), pointcloud.laz, mesh.ply, trueortho.tif, source_index.tif (la photo dont provient chaque cellule de la vraie orthophoto), occlusion.tif et seamlines.gpkg. Les caches (noyaux compilés, points caractéristiques des images) sont dans le dossier de cache de l'utilisateur (variable d'environnement TRUORTHO_CACHE_DIR ; truortho:environment l'affiche et le vide).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="212" />
            <source>orientation.json: the adjusted orientation.</source>
            <translation>orientation.json : l'orientation compensée.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="213" />
            <source>report.html (and report.json): the quality report of the run.</source>
            <translation>report.html (et report.json) : le rapport de qualité de l'exécution.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="214" />
            <source>dsm.tif: the filtered DSM (float32, nodata -9999).</source>
            <translation>dsm.tif : le MNS filtré (float32, NoData -9999).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="215" />
            <source>pointcloud.laz: the matched points with colour and confidence.</source>
            <translation>pointcloud.laz : les points appariés avec couleur et confiance.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="216" />
            <source>mesh.ply: 2.5D mesh of the filtered DSM with vertical walls and vertex colours.</source>
            <translation>mesh.ply : maillage 2,5D du MNS filtré avec murs verticaux et couleurs des sommets.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="217" />
            <source>trueortho.tif: the true orthophoto (bands of the photos + alpha, COG).</source>
            <translation>trueortho.tif : l'orthophoto vraie (bandes des photos + alpha, COG).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="218" />
            <source>occlusion.tif: 1 where no photo sees the surface.</source>
            <translation>occlusion.tif : 1 là où aucune photo ne voit la surface.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="219" />
            <source>seamlines.gpkg: one polygon per source photo.</source>
            <translation>seamlines.gpkg : un polygone par photo source.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="224" />
            <source>Dense image matching in object space (OSGM): computes a DSM directly on a ground grid from the oriented images, without rectification or pairwise depth maps. For every tile of the grid the images that see it (at most MAX_IMAGES) are resampled onto the horizontal plane of every search height (voxels of RESOLUTION x RESOLUTION x Z_STEP); a matching cost from all of them per cell and height is aggregated by semi-global matching along 8 or 16 paths (penalty P1 for a change of one height step, P2 for larger jumps, lowered across image edges), and each cell takes the height of least aggregated cost, refined between steps, with a confidence in [0, 1]. Matching runs coarse to fine over an image pyramid, by tiles, with progress and cancel. Cells without a reliable match are nodata (filter and fill them with truortho:dsmfilter). Optionally writes the confidence, an orthoimage coloured from the matched images, and a point cloud; with OBLIQUE = auto, groups of oblique images are matched in extra reference systems along their viewing directions, whose points (facades) go to the point cloud.</source>
            <translation>Appariement dense d'images dans l'espace objet (OSGM) : calcule un MNS directement sur une grille au sol à partir des images orientées, sans rectification épipolaire ni cartes de profondeur par paires. Pour chaque tuile de la grille, les images qui la voient (au plus MAX_IMAGES) sont rééchantillonnées sur le plan horizontal de chaque hauteur de recherche (voxels de RESOLUTION x RESOLUTION x Z_STEP) ; un coût d'appariement calculé à partir de toutes ces images par cellule et par hauteur est agrégé par appariement semi-global le long de 8 ou 16 chemins (pénalité P1 pour un changement d'un pas de hauteur, P2 pour les sauts plus grands, réduite aux contours de l'image), et chaque cellule prend la hauteur de moindre coût agrégé, affinée entre les pas, avec une confiance dans [0, 1]. L'appariement procède du grossier au fin sur une pyramide d'images, par tuiles, avec progression et annulation. Les cellules sans appariement fiable sont en NoData (les filtrer et les combler avec truortho:dsmfilter). Écrit en option la confiance, une orthoimage colorée à partir des images appariées et un nuage de points ; avec OBLIQUE = auto, des groupes d'images obliques sont appariés dans des systèmes de référence supplémentaires orientés selon leurs directions de visée, dont les points (façades) vont dans le nuage de points.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="238" />
            <source>Orientation JSON (from Orient images or Import orientation) with a projected CRS (metres) and at least two images, which must be on disk.</source>
            <translation>JSON d'orientation (issu de Orienter les images ou Importer une orientation) avec un SCR projeté (mètres) et au moins deux images, qui doivent être présentes sur le disque.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="240" />
            <source>Area to match (reprojected to the orientation's CRS); default the extent of the sparse points (1-99 %), else the union of the near-nadir image footprints. It must intersect the area the images see.</source>
            <translation>Zone à apparier (reprojetée dans le SCR de l'orientation) ; par défaut l'emprise des points épars (1-99 %), sinon l'union des emprises des images proches du nadir. Elle doit intersecter la zone vue par les images.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="243" />
            <source>Cell size of the DSM, metres; empty or 0 = the median ground sample distance of the near-nadir images.</source>
            <translation>Taille de cellule du MNS, en mètres ; vide ou 0 = taille médiane du pixel au sol des images proches du nadir.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="245" />
            <source>Height step between two search planes, metres; empty or 0 = the resolution. A larger step (1.5 x the resolution) is about 10 % faster, with crisper building edges and fewer holes, and noisier on flat ground.</source>
            <translation>Pas de hauteur entre deux plans de recherche, en mètres ; vide ou 0 = la résolution. Un pas plus grand (1,5 fois la résolution) est environ 10 % plus rapide, avec des bords de bâtiments plus nets et moins de trous, et plus bruité sur terrain plat.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="248" />
            <source>Lowest height searched (world Z, the orientation's vertical datum); empty = from the sparse points (0.5 % percentile minus a margin), else from the GCP heights. Must be below Z_MAX.</source>
            <translation>Hauteur minimale recherchée (Z terrain, dans le référentiel altimétrique de l'orientation) ; vide = à partir des points épars (centile 0,5 % moins une marge), sinon à partir des hauteurs des points d'appui. Doit être inférieure à Z_MAX.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="251" />
            <source>Highest height searched; empty = from the sparse points (99.5 % percentile plus a margin), else half the flying height above the highest GCP. Always kept below the cameras. Without sparse points or GCPs give Z_MIN and Z_MAX.</source>
            <translation>Hauteur maximale recherchée ; vide = à partir des points épars (centile 99,5 % plus une marge), sinon la moitié de la hauteur de vol au-dessus du point d'appui le plus haut. Toujours maintenue sous les caméras. Sans points épars ni points d'appui, indiquer Z_MIN et Z_MAX.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="254" />
            <source>Optional coarse DSM or DTM raster: the search at each cell is bounded by the lowest and highest height of its neighbourhood plus a margin, which speeds up matching and avoids wrong heights on rough terrain.</source>
            <translation>Raster MNS ou MNT grossier facultatif : la recherche en chaque cellule est bornée par les hauteurs minimale et maximale de son voisinage plus une marge, ce qui accélère l'appariement et évite des hauteurs erronées sur un terrain accidenté.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="257" />
            <source>Number of aggregation directions of semi-global matching: 16 (the default) or 8 (about 6 % faster; the hillshade of natural terrain then shows a fine cross-hatch along the grid's axes and diagonals).</source>
            <translation>Nombre de directions d'agrégation de l'appariement semi-global : 16 (par défaut) ou 8 (environ 6 % plus rapide ; l'ombrage d'un terrain naturel montre alors un fin quadrillage le long des axes et des diagonales de la grille).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="260" />
            <source>none: one nadir reference system (the DSM). auto: groups of oblique images also get reference systems along their viewing directions, whose points go to the point cloud with their 'system' id (without a POINT_CLOUD output they are skipped: the DSM is the same).</source>
            <translation>none : un seul système de référence au nadir (le MNS). auto : les groupes d'images obliques reçoivent en plus des systèmes de référence orientés selon leurs directions de visée, dont les points vont dans le nuage de points avec leur identifiant 'system' (sans sortie POINT_CLOUD, ils sont omis : le MNS est le même).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="263" />
            <source>Penalty for a change of one height step between neighbouring cells, in cost units (unrelated image windows cost 1023); empty = 256.</source>
            <translation>Pénalité pour un changement d'un pas de hauteur entre cellules voisines, en unités de coût (des fenêtres d'image sans rapport coûtent 1023) ; vide = 256.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="265" />
            <source>Penalty for a larger height jump, above P1 and at most 3072; empty = 2048 (a jump then needs contrary evidence from two cells).</source>
            <translation>Pénalité pour un saut de hauteur plus grand, supérieure à P1 et au plus 3072 ; vide = 2048 (un saut exige alors des indices contraires provenant de deux cellules).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="267" />
            <source>Largest number of images matched per tile (best coverage first, then the most nadir; more only where fewer would leave part of the tile with under 2 views); memory and time grow with it.</source>
            <translation>Nombre maximal d'images appariées par tuile (meilleure couverture d'abord, puis les plus proches du nadir ; davantage seulement là où moins laisseraient une partie de la tuile avec moins de 2 vues) ; la mémoire et le temps de calcul augmentent avec lui.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="270" />
            <source>Tile side in cells; memory grows with its square, the number of search heights and MAX_IMAGES.</source>
            <translation>Côté des tuiles en cellules ; la mémoire croît avec son carré, le nombre de hauteurs de recherche et MAX_IMAGES.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="272" />
            <source>Where the tiles are matched; the DSM and confidence are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the images at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. Finished tiles are kept beside the DSM (DSM.tif.tiles) until the run ends, so a rerun with the same inputs and parameters after a crash reuses them.</source>
            <translation>Où les tuiles sont appariées ; le MNS et la confiance sont identiques quel que soit le choix. inprocess : dans le processus de QGIS, une tuile après l'autre sur tous les cœurs (par défaut). local : une grappe Dask de processus de travail sur cet ordinateur, à l'écoute sur 127.0.0.1 seulement (un processus par cœur, chacun avec une limite de mémoire). scheduler : une grappe Dask existante, donnée par SCHEDULER_ADDRESS ; ses processus de travail doivent lire les images aux mêmes chemins (stockage partagé) et avoir TruOrtho installé. Les tuiles d'un processus de travail qui meurt sont recalculées par les autres. Les tuiles terminées sont gardées à côté du MNS (DSM.tif.tiles) jusqu'à la fin du traitement, de sorte qu'une nouvelle exécution avec les mêmes entrées et paramètres après un plantage les réutilise.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="281" />
            <source>The raw DSM: GeoTIFF, float32, in the orientation's CRS, nodata -9999.</source>
            <translation>Le MNS brut : GeoTIFF, float32, dans le SCR de l'orientation, NoData -9999.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="282" />
            <source>Optional confidence GeoTIFF (float32 in [0, 1], nodata -1) on the DSM grid, for truortho:dsmfilter.</source>
            <translation>GeoTIFF de confiance facultatif (float32 dans [0, 1], NoData -1) sur la grille du MNS, pour truortho:dsmfilter.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="284" />
            <source>Optional RGB orthoimage GeoTIFF (uint8, 0 = no data) on the DSM grid, coloured from the matched images; not a true orthophoto (use truortho:trueortho for that).</source>
            <translation>Orthoimage RVB facultative en GeoTIFF (uint8, 0 = pas de données) sur la grille du MNS, colorée à partir des images appariées ; ce n'est pas une orthophoto vraie (utiliser truortho:trueortho pour cela).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="286" />
            <source>Optional point cloud (.laz or .las; LAS 1.4 with colours, 'confidence' and 'system', the reference system of each point).</source>
            <translation>Nuage de points facultatif (.laz ou .las ; LAS 1.4 avec couleurs, 'confidence' et 'system', le système de référence de chaque point).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="288" />
            <source>JSON: grid size, resolution, height step and range (and where it came from), pyramid levels, tiles, completeness, mean confidence, reference systems, time.</source>
            <translation>JSON : taille de la grille, résolution, pas et plage de hauteur (et leur origine), niveaux de pyramide, tuiles, complétude, confiance moyenne, systèmes de référence, durée.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="294" />
            <source>Computes a true orthophoto from oriented images and a surface (a DSM raster such as OSGM's, or a PLY/OBJ mesh): every cell is coloured from an image that really sees it, found with a depth buffer of the surface per image (DSM cells as flat tops with vertical walls at height steps, or the mesh's triangles; frustum and back-face culling). Among the images that see a cell the one with the finest effective ground resolution (distance and incidence on the surface) is preferred; roofs are textured from one image each and seamlines follow height discontinuities and avoid places where the images disagree (label smoothing), with feathering across seams only between images that both see the cells. Per-image colour corrections (a gain/offset per RGB channel for white balance and exposure, then one in CIE L*a*b*; per-band gain/offset for non-RGB data) are estimated by least squares from cells seen by several images. Cells no image sees get alpha 0 and appear in the occlusion mask. Any band count and data type of the images is kept (RGB, 16-bit panchromatic, thermal). Processing runs by tiles with bounded memory; progress and cancel per tile.</source>
            <translation>Calcule une orthophoto vraie à partir d'images orientées et d'une surface (un raster MNS comme celui d'OSGM, ou un maillage PLY/OBJ) : chaque cellule est colorée à partir d'une image qui la voit réellement, déterminée avec un tampon de profondeur de la surface par image (cellules du MNS comme sommets plats avec murs verticaux aux sauts de hauteur, ou les triangles du maillage ; élimination hors du champ de vue et des faces arrière). Parmi les images qui voient une cellule, celle de résolution au sol effective la plus fine (distance et incidence sur la surface) est préférée ; les toits sont texturés chacun à partir d'une seule image et les lignes de raccord suivent les discontinuités de hauteur et évitent les endroits où les images divergent (lissage des étiquettes), avec un fondu à travers les raccords uniquement entre images qui voient toutes deux les cellules. Des corrections colorimétriques par image (un gain/décalage par canal RVB pour la balance des blancs et l'exposition, puis dans CIE L*a*b* ; gain/décalage par bande pour les données non RVB) sont estimées par moindres carrés à partir des cellules vues par plusieurs images. Les cellules qu'aucune image ne voit reçoivent un alpha de 0 et apparaissent dans le masque d'occultation. Le nombre de bandes et le type de données des images sont conservés (RVB, panchromatique 16 bits, thermique). Le traitement se fait par tuiles avec une mémoire bornée ; progression et annulation par tuile.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="309" />
            <source>Orientation JSON (from Orient images or Import orientation); its images must be on disk.</source>
            <translation>JSON d'orientation (issu de Orienter les images ou Importer une orientation) ; ses images doivent être présentes sur le disque.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="311" />
            <source>DSM GeoTIFF (any CRS; resampled onto the output grid by nearest neighbour) or a PLY/OBJ mesh. Heights must use the orientation's vertical datum. It must cover the extent.</source>
            <translation>GeoTIFF MNS (SCR quelconque ; rééchantillonné sur la grille de sortie au plus proche voisin) ou un maillage PLY/OBJ. Les hauteurs doivent être dans le référentiel altimétrique de l'orientation. Il doit couvrir l'emprise.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="313" />
            <source>Output extent; default the surface's extent.</source>
            <translation>Emprise de sortie ; par défaut l'emprise de la surface.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="314" />
            <source>Output cell size in units of the output CRS; 0 = the DSM's cell size.</source>
            <translation>Taille de cellule de sortie dans les unités du SCR de sortie ; 0 = taille de cellule du MNS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="315" />
            <source>Output CRS; default the orientation's. When it differs, the computation runs on the output grid and cell centres are transformed to the orientation's CRS (images are resampled once).</source>
            <translation>SCR de sortie ; par défaut celui de l'orientation. S'il diffère, le calcul se fait sur la grille de sortie et les centres des cellules sont transformés dans le SCR de l'orientation (les images ne sont rééchantillonnées qu'une fois).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="318" />
            <source>Estimate and apply per-image colour corrections before mosaicking.</source>
            <translation>Estimer et appliquer des corrections colorimétriques par image avant le mosaïquage.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="319" />
            <source>With the colour correction: estimate a radial darkening towards the image corners per camera from the overlaps and remove it first. Images without vignetting get a factor of about 1; switch it off for images already corrected in processing.</source>
            <translation>Avec la correction colorimétrique : estimer par caméra, à partir des recouvrements, l'assombrissement radial vers les coins de l'image et le supprimer d'abord. Les images sans vignettage reçoivent un facteur proche de 1 ; à désactiver pour des images déjà corrigées au développement.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="327" />
            <source>Largest off-nadir angle of the viewing ray (degrees) for an image to texture a cell; also bounds how far outside a tile occluders are searched.</source>
            <translation>Angle maximal du rayon de visée par rapport au nadir (degrés) pour qu'une image texture une cellule ; limite aussi jusqu'où, hors d'une tuile, les objets occultants sont recherchés.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="329" />
            <source>Width of the feathering across seamlines, in cells (0 = hard seams).</source>
            <translation>Largeur du fondu aux lignes de raccord, en cellules (0 = raccords francs).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="330" />
            <source>Tile side in cells; memory grows with its square and the images per tile.</source>
            <translation>Côté des tuiles en cellules ; la mémoire croît avec son carré et le nombre d'images par tuile.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="331" />
            <source>Compression of the orthophoto. DEFLATE (the default), ZSTD and LZW are lossless: DEFLATE gives the smallest files and every GIS reads it; ZSTD (level 1) writes about twice as fast and about 9 % larger (GDAL 2.3 or later reads it); LZW is for older readers. JPEG is lossy (about a fifth of the size), for 8-bit RGB images only: RGB is stored as YCbCr with halved colour resolution, so colours blur across sharp edges such as building outlines (deliver and view with it; measure on a lossless one), and the alpha band becomes the file's internal mask. The source index and occlusion mask always stay lossless.</source>
            <translation>Compression de l'orthophoto. DEFLATE (par défaut), ZSTD et LZW sont sans perte : DEFLATE donne les fichiers les plus petits et tous les SIG le lisent ; ZSTD (niveau 1) écrit environ deux fois plus vite, pour des fichiers environ 9 % plus gros (lisible à partir de GDAL 2.3) ; LZW sert aux lecteurs anciens. JPEG est avec perte (environ un cinquième de la taille), pour les images RVB 8 bits seulement : le RVB est stocké en YCbCr avec une résolution des couleurs réduite de moitié, si bien que les couleurs bavent au travers des arêtes franches comme les contours des bâtiments (pour livrer et visualiser ; mesurer sur un fichier sans perte), et la bande alpha devient le masque interne du fichier. L'index des images sources et le masque d'occultation restent toujours sans perte.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="338" />
            <source>JPEG quality (1-100) when COMPRESSION is JPEG.</source>
            <translation>Qualité JPEG (1-100) lorsque COMPRESSION vaut JPEG.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="339" />
            <source>Where the tiles of the mosaic are computed; the true orthophoto, source index, occlusion mask and seamlines are identical with every choice. inprocess: in QGIS's process, the independent tiles of a wave in parallel threads (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the images and the surface at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The colour correction (on a decimated grid) is estimated in QGIS's process. Finished tiles are kept in a folder beside the output (its name plus '.tiles') until the run succeeds, so a rerun with the same inputs and parameters after a crash reuses them.</source>
            <translation>Où les tuiles de la mosaïque sont calculées ; l'orthophoto vraie, l'index des images sources, le masque d'occultation et les lignes de raccord sont identiques quel que soit le choix. inprocess : dans le processus de QGIS, les tuiles indépendantes d'une vague en parallèle dans des threads (par défaut). local : une grappe Dask de processus de travail sur cet ordinateur, à l'écoute sur 127.0.0.1 seulement (un processus par cœur, chacun avec une limite de mémoire). scheduler : une grappe Dask existante, donnée par SCHEDULER_ADDRESS ; ses processus de travail doivent lire les images et la surface aux mêmes chemins (stockage partagé) et avoir TruOrtho installé. Les tuiles d'un processus de travail qui meurt sont recalculées par les autres. La correction colorimétrique (sur une grille décimée) est estimée dans le processus de QGIS. Les tuiles terminées sont gardées dans un dossier à côté de la sortie (son nom suivi de « .tiles ») jusqu'à la réussite du traitement, de sorte qu'une nouvelle exécution avec les mêmes entrées et paramètres après un plantage les réutilise.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="351" />
            <source>GeoTIFF with the images' bands and data type plus an alpha band (an internal mask with JPEG compression), tiled, with overviews, Cloud-Optimized GeoTIFF layout.</source>
            <translation>GeoTIFF avec les bandes et le type de données des images plus une bande alpha (un masque interne avec la compression JPEG), tuilé, avec aperçus, au format Cloud-Optimized GeoTIFF.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="353" />
            <source>Int16 GeoTIFF: index (0-based, orientation order) of the image each cell comes from; -1 = nodata.</source>
            <translation>GeoTIFF Int16 : index (à partir de 0, dans l'ordre de l'orientation) de l'image dont provient chaque cellule ; -1 = NoData.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="355" />
            <source>UInt8 GeoTIFF: 1 where no image sees the cell, 0 where seen, 255 where the surface has no data.</source>
            <translation>GeoTIFF UInt8 : 1 là où aucune image ne voit la cellule, 0 là où elle est vue, 255 là où la surface n'a pas de données.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="357" />
            <source>Polygons, one feature per source image: the cells it colours (image_index, image, cells, area).</source>
            <translation>Polygones, une entité par image source : les cellules qu'elle colore (image_index, image, cells, area).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="363" />
            <source>Cleans a raw DSM (e.g. the dense-matching DSM of TruOrtho's OSGM step) tile by tile: snaps the cells of blurred height steps to the nearer side, removes outliers (cells that depart from the confidence-weighted median of their window by more than the threshold and have too few neighbours at their height, so roof edges and corners survive), fills holes up to a maximum width by harmonic interpolation (holes at the foot of walls from the ground side only; wider holes stay nodata and are reported), and optionally smooths planar surfaces without blurring their edges. Optionally derives a terrain model (DTM) by SMRF-style ground filtering and the normalised DSM (height above terrain). Outputs keep the input's CRS, grid and nodata; the statistics (removed outliers, filled cells, remaining holes) are returned and logged.</source>
            <translation>Nettoie un MNS brut (par ex. le MNS d'appariement dense de l'étape OSGM de TruOrtho) tuile par tuile : ramène les cellules des sauts de hauteur flous du côté le plus proche, supprime les valeurs aberrantes (cellules qui s'écartent de plus que le seuil de la médiane pondérée par la confiance de leur fenêtre et ont trop peu de voisins à leur hauteur, de sorte que les bords et les angles des toits sont préservés), comble les trous jusqu'à une largeur maximale par interpolation harmonique (trous au pied des murs uniquement depuis le côté du sol ; les trous plus larges restent en NoData et sont signalés), et lisse en option les surfaces planes sans en estomper les arêtes. Dérive en option un modèle numérique de terrain (MNT) par un filtrage du sol de type SMRF, ainsi que le MNS normalisé (hauteur au-dessus du terrain). Les sorties conservent le SCR, la grille et le NoData de l'entrée ; les statistiques (valeurs aberrantes supprimées, cellules comblées, trous restants) sont renvoyées et journalisées.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="374" />
            <source>Raw DSM: single-band raster with a projected CRS (metres); its nodata cells are holes.</source>
            <translation>MNS brut : raster à une bande dans un SCR projeté (mètres) ; ses cellules NoData sont des trous.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="375" />
            <source>Optional confidence raster in [0, 1] (OSGM's CONFIDENCE): cells below the minimum confidence are removed, less confident cells must agree better with their neighbours, and the median is weighted by confidence.</source>
            <translation>Raster de confiance facultatif dans [0, 1] (CONFIDENCE d'OSGM) : les cellules sous la confiance minimale sont supprimées, les cellules moins fiables doivent mieux concorder avec leurs voisines, et la médiane est pondérée par la confiance.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="378" />
            <source>Largest departure from the neighbourhood median, metres (empty: 4 x the resolution).</source>
            <translation>Écart maximal à la médiane du voisinage, en mètres (vide : 4 x la résolution).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="380" />
            <source>Side of the median window in cells (odd); a second pass uses twice the window.</source>
            <translation>Côté de la fenêtre médiane en cellules (impair) ; une seconde passe utilise une fenêtre deux fois plus grande.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="382" />
            <source>Neighbours within the threshold of a cell's height that keep it although it departs from the median (edges, corners, thin structures).</source>
            <translation>Voisins à moins du seuil de la hauteur d'une cellule qui la conservent bien qu'elle s'écarte de la médiane (arêtes, angles, structures fines).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="384" />
            <source>With a confidence raster: cells below this confidence are removed.</source>
            <translation>Avec un raster de confiance : les cellules sous cette confiance sont supprimées.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="385" />
            <source>With a confidence raster: less confident cells are removed when they depart by more than the threshold from the median of the cells at least this confident in their 15 x 15 window (0: off).</source>
            <translation>Avec un raster de confiance : les cellules moins fiables sont supprimées lorsqu'elles s'écartent de plus que le seuil de la médiane des cellules ayant au moins cette confiance dans leur fenêtre de 15 x 15 (0 : désactivé).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="388" />
            <source>Largest hole width (metres) that is interpolated; 0 fills nothing.</source>
            <translation>Largeur maximale de trou (mètres) interpolée ; 0 ne comble rien.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="389" />
            <source>Height difference between two surfaces (a wall), metres: hole boundary cells that much above nearby boundary cells are not interpolated from.</source>
            <translation>Différence de hauteur entre deux surfaces (un mur), en mètres : les cellules du bord d'un trou situées d'autant plus haut que les cellules de bord voisines ne servent pas à l'interpolation.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="391" />
            <source>Snap the cells of blurred height steps (between the two levels of their 5 x 5 window) to the nearer level.</source>
            <translation>Ramener les cellules des sauts de hauteur flous (entre les deux niveaux de leur fenêtre de 5 x 5) au niveau le plus proche.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="393" />
            <source>Replace cells by a local plane fitted to the neighbours at their height (flat and pitched roofs, streets); steps stay sharp.</source>
            <translation>Remplacer les cellules par un plan local ajusté aux voisines à leur hauteur (toits plats et en pente, rues) ; les sauts restent nets.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="395" />
            <source>Radius of the smoothing neighbourhood, cells.</source>
            <translation>Rayon du voisinage de lissage, en cellules.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="396" />
            <source>Neighbours within this height of a cell belong to its surface, metres (empty: 2.5 x the resolution).</source>
            <translation>Les voisines à moins de cette hauteur d'une cellule appartiennent à sa surface, en mètres (vide : 2,5 x la résolution).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="398" />
            <source>Cell size of the ground filter, metres (empty: max(1 m, the DSM resolution)); the DTM is written on the DSM grid.</source>
            <translation>Taille de cellule du filtre de sol, en mètres (vide : max(1 m, résolution du MNS)) ; le MNT est écrit sur la grille du MNS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="400" />
            <source>Largest opening radius of the ground filter, metres: more than half the width of the largest building.</source>
            <translation>Rayon d'ouverture maximal du filtre de sol, en mètres : plus de la moitié de la largeur du plus grand bâtiment.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="402" />
            <source>Terrain slope (rise over run) the ground filter keeps as ground.</source>
            <translation>Pente du terrain (dénivelé sur distance) que le filtre de sol conserve comme sol.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="403" />
            <source>Where the tiles are filtered; the filtered DSM and the statistics are identical with every choice. inprocess: in QGIS's process, one tile after the other on all cores (the default). local: a Dask cluster of worker processes on this computer, listening on 127.0.0.1 only (one worker per core, a memory limit each). scheduler: an existing Dask cluster given by SCHEDULER_ADDRESS; its workers must read the DSM and the confidence raster at the same paths (shared storage) and have TruOrtho installed. A worker that dies has its tiles recomputed by the others. The terrain model is computed in QGIS's process.</source>
            <translation>Où les tuiles sont filtrées ; le MNS filtré et les statistiques sont identiques quel que soit le choix. inprocess : dans le processus de QGIS, une tuile après l'autre sur tous les cœurs (par défaut). local : une grappe Dask de processus de travail sur cet ordinateur, à l'écoute sur 127.0.0.1 seulement (un processus par cœur, chacun avec une limite de mémoire). scheduler : une grappe Dask existante, donnée par SCHEDULER_ADDRESS ; ses processus de travail doivent lire le MNS et le raster de confiance aux mêmes chemins (stockage partagé) et avoir TruOrtho installé. Les tuiles d'un processus de travail qui meurt sont recalculées par les autres. Le modèle de terrain est calculé dans le processus de QGIS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="411" />
            <source>Filtered DSM (GeoTIFF, float32).</source>
            <translation>MNS filtré (GeoTIFF, float32).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="412" />
            <source>Optional terrain model (GeoTIFF, float32, DSM grid).</source>
            <translation>Modèle numérique de terrain facultatif (GeoTIFF, float32, grille du MNS).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="413" />
            <source>Optional normalised DSM: DSM minus DTM, heights above the terrain.</source>
            <translation>MNS normalisé facultatif : MNS moins MNT, hauteurs au-dessus du terrain.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="414" />
            <source>JSON: the filter statistics (and the ground filter's).</source>
            <translation>JSON : les statistiques du filtre (et celles du filtre de sol).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="415" />
            <source>Cells removed as outliers or for low confidence.</source>
            <translation>Cellules supprimées comme valeurs aberrantes ou pour confiance insuffisante.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="416" />
            <source>Hole cells interpolated.</source>
            <translation>Cellules de trous interpolées.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="417" />
            <source>Holes wider than MAX_HOLE, left as nodata.</source>
            <translation>Trous plus larges que MAX_HOLE, laissés en NoData.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="422" />
            <source>Builds a triangle mesh. From a DSM: a 2.5D mesh whose height steps are vertical walls (no triangle ever spans a step) and whose flat and smooth areas are decimated by a restricted quadtree with a guaranteed vertical error bound at every cell centre; vertex colours from an optional orthoimage. From a point cloud (LAS/LAZ or EPT, e.g. merged oblique matching): one 2.5D Delaunay mesh per reference system, seen along its viewing direction (overlapping layers where systems see the same surface; not watertight). Writes PLY (binary) or OBJ, in the CRS or in a local frame whose offset is recorded in the header; truortho:trueortho reads it as SURFACE.</source>
            <translation>Construit un maillage triangulaire. À partir d'un MNS : un maillage 2,5D dont les sauts de hauteur sont des murs verticaux (aucun triangle n'enjambe jamais un saut) et dont les zones planes et lisses sont décimées par un quadtree restreint avec une borne garantie de l'erreur verticale au centre de chaque cellule ; couleurs des sommets issues d'une orthoimage facultative. À partir d'un nuage de points (LAS/LAZ ou EPT, par ex. l'appariement fusionné d'images obliques) : un maillage de Delaunay 2,5D par système de référence, vu selon sa direction de visée (couches superposées là où des systèmes voient la même surface ; non étanche). Écrit du PLY (binaire) ou de l'OBJ, dans le SCR ou dans un repère local dont le décalage est consigné dans l'en-tête ; truortho:trueortho le lit comme SURFACE.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="431" />
            <source>DSM raster (projected CRS) or point cloud (.las, .laz, or an EPT ept.json).</source>
            <translation>Raster MNS (SCR projeté) ou nuage de points (.las, .laz, ou un ept.json EPT).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="432" />
            <source>Optional orthoimage (RGB) for the vertex colours of a DSM mesh.</source>
            <translation>Orthoimage facultative (RVB) pour les couleurs des sommets d'un maillage de MNS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="433" />
            <source>Largest vertical difference between mesh and DSM at any cell centre, metres (empty: half the DSM resolution).</source>
            <translation>Écart vertical maximal entre le maillage et le MNS en tout centre de cellule, en mètres (vide : la moitié de la résolution du MNS).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="435" />
            <source>Smallest height difference between neighbouring cells that becomes a wall, metres.</source>
            <translation>Plus petite différence de hauteur entre cellules voisines qui devient un mur, en mètres.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="436" />
            <source>Steepest slope kept as sloping triangles, degrees: the step threshold is max(MIN_STEP, resolution x tan(MAX_SLOPE)).</source>
            <translation>Pente la plus forte conservée en triangles inclinés, en degrés : le seuil de saut vaut max(MIN_STEP, résolution x tan(MAX_SLOPE)).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="438" />
            <source>Largest block of cells one pair of triangles may cover (a power of two).</source>
            <translation>Plus grand bloc de cellules qu'une paire de triangles peut couvrir (une puissance de deux).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="439" />
            <source>Point clouds: longest triangle edge, metres (empty: 4 x the median point spacing).</source>
            <translation>Nuages de points : arête de triangle la plus longue, en mètres (vide : 4 x l'espacement médian des points).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="440" />
            <source>CRS: world coordinates (PLY doubles). Local: world minus an offset recorded as 'comment offset E N H' (PLY) or '# offset E N H' (OBJ), for viewers that need small numbers.</source>
            <translation>SCR : coordonnées terrain (doubles PLY). Local : terrain moins un décalage consigné sous la forme 'comment offset E N H' (PLY) ou '# offset E N H' (OBJ), pour les visionneuses qui ont besoin de petits nombres.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="442" />
            <source>The mesh: .ply (binary little-endian, 'comment crs ...') or .obj ('# crs ...', vertex colours as 'v x y z r g b').</source>
            <translation>Le maillage : .ply (binaire petit-boutiste, 'comment crs ...') ou .obj ('# crs ...', couleurs des sommets sous la forme 'v x y z r g b').</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="444" />
            <source>Number of vertices.</source>
            <translation>Nombre de sommets.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="445" />
            <source>Number of triangles.</source>
            <translation>Nombre de triangles.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="446" />
            <source>Number of vertical wall triangles (DSM meshes).</source>
            <translation>Nombre de triangles de murs verticaux (maillages de MNS).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="451" />
            <source>Exports a DSM as a point cloud, one point per valid cell centre, with colours from an orthoimage and per-point confidence from a confidence raster: LAS 1.4 or LAZ (point format 7, CRS as WKT, extra dimensions 'confidence' and 'system' (the reference system), a TruOrtho VLR describing the reference systems), readable by PDAL, laspy, LAStools and CloudCompare. An Entwine Point Tile (EPT) dataset is written beside it: QGIS builds without PDAL (as Debian's QGIS 3.22) open it as a point cloud layer (menu Layer, Add Layer, Add Point Cloud Layer; choose ept.json).</source>
            <translation>Exporte un MNS en nuage de points, un point par centre de cellule valide, avec les couleurs d'une orthoimage et une confiance par point issue d'un raster de confiance : LAS 1.4 ou LAZ (format de point 7, SCR en WKT, dimensions supplémentaires 'confidence' et 'system' (le système de référence), un VLR TruOrtho décrivant les systèmes de référence), lisible par PDAL, laspy, LAStools et CloudCompare. Un jeu de données Entwine Point Tile (EPT) est écrit à côté : les versions de QGIS sans PDAL (comme QGIS 3.22 de Debian) l'ouvrent comme couche nuage de points (menu Couche, Ajouter une couche, Ajouter une couche nuage de points ; choisir ept.json).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="460" />
            <source>DSM raster with a projected CRS.</source>
            <translation>Raster MNS dans un SCR projeté.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="461" />
            <source>Optional orthoimage (RGB) for the point colours.</source>
            <translation>Orthoimage facultative (RVB) pour les couleurs des points.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="462" />
            <source>Optional confidence raster in [0, 1], stored as the 'confidence' dimension.</source>
            <translation>Raster de confiance facultatif dans [0, 1], stocké comme dimension 'confidence'.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="463" />
            <source>The point cloud (.laz compressed, or .las).</source>
            <translation>Le nuage de points (.laz compressé, ou .las).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="464" />
            <source>Folder of the EPT dataset (ept.json, ept-data/, ept-hierarchy/); leave empty to skip.</source>
            <translation>Dossier du jeu de données EPT (ept.json, ept-data/, ept-hierarchy/) ; laisser vide pour ne pas l'écrire.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="465" />
            <source>Path of the EPT dataset's ept.json.</source>
            <translation>Chemin du fichier ept.json du jeu de données EPT.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="466" />
            <source>Number of points written.</source>
            <translation>Nombre de points écrits.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="471" />
            <source>Merges point clouds of several reference systems (e.g. the nadir and oblique systems of dense matching) into one LAS 1.4 / LAZ file, keeping each point's 'system' (files without it get the index of their file) and confidence; optionally thins duplicates on a voxel grid, keeping the most confident point of each voxel; optionally writes an EPT dataset for QGIS.</source>
            <translation>Fusionne des nuages de points de plusieurs systèmes de référence (par ex. les systèmes nadir et obliques de l'appariement dense) en un seul fichier LAS 1.4 / LAZ, en conservant le 'system' de chaque point (les fichiers qui n'en ont pas reçoivent l'index de leur fichier) et sa confiance ; éclaircit en option les doublons sur une grille de voxels en gardant le point le plus fiable de chaque voxel ; écrit en option un jeu de données EPT pour QGIS.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="477" />
            <source>LAS/LAZ files in one CRS.</source>
            <translation>Fichiers LAS/LAZ dans un même SCR.</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="478" />
            <source>Voxel size for thinning, metres (empty: keep every point).</source>
            <translation>Taille des voxels pour l'éclaircissement, en mètres (vide : conserver tous les points).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="479" />
            <source>The merged point cloud (.laz or .las).</source>
            <translation>Le nuage de points fusionné (.laz ou .las).</translation>
        </message>
        <message>
            <location filename="../processing/help/__init__.py" line="480" />
            <source>Optional folder for an EPT dataset of the merged cloud.</source>
            <translation>Dossier facultatif pour un jeu de données EPT du nuage fusionné.</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="222" />
            <source>GCP</source>
            <translation>Point d'appui</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="330" />
            <source>Observation</source>
            <translation>Observation</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="371" />
            <source>GCPS and OBSERVATIONS must be given together</source>
            <translation>GCPS et OBSERVATIONS doivent être fournis ensemble</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="54" />
            <source>QGIS cannot read the CRS {!r}</source>
            <translation>QGIS ne peut pas lire le SCR {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="185" />
            <source>{}: expected a finite number, got {!r}</source>
            <translation>{} : nombre fini attendu, reçu {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="194" />
            <source>{} layer {!r} lacks the field(s) {}; expected fields: {}</source>
            <translation>Couche {} {!r} : champ(s) manquant(s) {} ; champs attendus : {}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="313" />
            <source>Observation table {!r}, feature {}: sigma must be positive, got {}</source>
            <translation>Table d'observations {!r}, entité {} : sigma doit être positif, reçu {}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="183" />
            <source>{}: expected a number, got {!r}</source>
            <translation>{} : nombre attendu, reçu {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="244" />
            <source>GCP layer {!r}: feature {} has no name</source>
            <translation>Couche de points d'appui {!r} : l'entité {} n'a pas de nom</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="249" />
            <source>GCP layer {!r}: the name {!r} appears twice</source>
            <translation>Couche de points d'appui {!r} : le nom {!r} apparaît deux fois</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="255" />
            <source>GCP layer {!r}: GCP {!r} has no geometry</source>
            <translation>Couche de points d'appui {!r} : le point d'appui {!r} n'a pas de géométrie</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="263" />
            <source>GCP layer {!r}: GCP {!r} is not a single point</source>
            <translation>Couche de points d'appui {!r} : le point d'appui {!r} n'est pas un point simple</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="269" />
            <source>GCP layer {!r}: GCP {!r} has no height: use PointZ geometries or a 'z' field</source>
            <translation>Couche de points d'appui {!r} : le point d'appui {!r} n'a pas de hauteur : utilisez des géométries PointZ ou un champ 'z'</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="339" />
            <source>Observation table {!r}, feature {}: unknown GCP {!r}</source>
            <translation>Table d'observations {!r}, entité {} : point d'appui inconnu {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="345" />
            <source>Observation table {!r}, feature {}: unknown image {!r}</source>
            <translation>Table d'observations {!r}, entité {} : image inconnue {!r}</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="353" />
            <source>Observation table {!r}, feature {}: x and y are required</source>
            <translation>Table d'observations {!r}, entité {} : x et y sont obligatoires</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="283" />
            <source>GCP layer {!r}: GCP {!r} has role {!r}; expected 'gcp' or 'check'</source>
            <translation>Couche de points d'appui {!r} : le point d'appui {!r} a le rôle {!r} ; 'gcp' ou 'check' attendu</translation>
        </message>
        <message>
            <location filename="../processing/layers.py" line="296" />
            <source>GCP {!r}: sigmas must be positive</source>
            <translation>Point d'appui {!r} : les sigmas doivent être positifs</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="59" />
            <source>TruOrtho</source>
            <translation>TruOrtho</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="62" />
            <source>TruOrtho {} — orientation, dense matching and true orthophotos</source>
            <translation>TruOrtho {} — orientation, appariement dense et orthophotos vraies</translation>
        </message>
        <message>
            <location filename="../processing/provider.py" line="96" />
            <source>TruOrtho model {} could not be loaded</source>
            <translation>Le modèle TruOrtho {} n'a pas pu être chargé</translation>
        </message>
        <message>
            <location filename="../processing/styles.py" line="73" />
            <source>seen by no image</source>
            <translation>vu par aucune image</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="212" />
            <source>Load measurements from a CSV table or gcp_list.txt</source>
            <translation>Charger les mesures depuis une table CSV ou un gcp_list.txt</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="107" />
            <source>GCP measurements</source>
            <translation>Mesures des points d'appui</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="140" />
            <source>Folder of the photos</source>
            <translation>Dossier des photos</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="144" />
            <source>Images</source>
            <translation>Images</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="148" />
            <source>GCP layer</source>
            <translation>Couche des points d'appui</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="151" />
            <source>Optional: orientation to predict the GCPs in the images</source>
            <translation>Facultatif : orientation pour prédire les points d'appui dans les images</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="161" />
            <source>Load</source>
            <translation>Charger</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="161" />
            <source>Read the images, the GCPs and the orientation</source>
            <translation>Lire les images, les points d'appui et l'orientation</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="165" />
            <source>Undo</source>
            <translation>Annuler</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="165" />
            <source>Undo (Ctrl+Z)</source>
            <translation>Annuler (Ctrl+Z)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="166" />
            <source>Redo</source>
            <translation>Rétablir</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="166" />
            <source>Redo (Ctrl+Shift+Z)</source>
            <translation>Rétablir (Ctrl+Maj+Z)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="168" />
            <source>Delete</source>
            <translation>Supprimer</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="169" />
            <source>Delete the measurement of the current GCP in this image (Del)</source>
            <translation>Supprimer la mesure du point d'appui courant dans cette image (Suppr)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="173" />
            <source>Refine</source>
            <translation>Affiner</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="174" />
            <source>Measure the current GCP in its other images by least-squares matching from this image's measurement (needs an orientation)</source>
            <translation>Mesurer le point d'appui courant dans ses autres images par corrélation par moindres carrés à partir de la mesure de cette image (nécessite une orientation)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="203" />
            <source>Click: place the current GCP; drag: pan; wheel: zoom</source>
            <translation>Clic : placer le point d'appui courant ; glisser : déplacer la vue ; molette : zoomer</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="257" />
            <source>Orientations (*.json *.txt);;All files (*)</source>
            <translation>Orientations (*.json *.txt);;Tous les fichiers (*)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="361" />
            <source>predicted</source>
            <translation>prédit</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="361" />
            <source>not measured</source>
            <translation>non mesuré</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="556" />
            <source>Save the observation table</source>
            <translation>Enregistrer la table des observations</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="556" />
            <source>CSV (*.csv)</source>
            <translation>CSV (*.csv)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="562" />
            <source>Save gcp_list.txt</source>
            <translation>Enregistrer gcp_list.txt</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="563" />
            <source>gcp_list (*.txt)</source>
            <translation>gcp_list (*.txt)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="568" />
            <source>Open measurements</source>
            <translation>Ouvrir des mesures</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="569" />
            <source>Observation tables (*.csv *.txt)</source>
            <translation>Tables d'observations (*.csv *.txt)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="143" />
            <source>Choose the image folder</source>
            <translation>Choisir le dossier des images</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="155" />
            <source>Choose an orientation file</source>
            <translation>Choisir un fichier d'orientation</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="194" />
            <source>Previous image (Page Up)</source>
            <translation>Image précédente (Page préc.)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="195" />
            <source>Next image (Page Down)</source>
            <translation>Image suivante (Page suiv.)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="196" />
            <source>Previous GCP (Ctrl+Page Up)</source>
            <translation>Point d'appui précédent (Ctrl+Page préc.)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="197" />
            <source>Next GCP (Ctrl+Page Down)</source>
            <translation>Point d'appui suivant (Ctrl+Page suiv.)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="198" />
            <source>Fit</source>
            <translation>Ajuster</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="198" />
            <source>Show the whole image (F)</source>
            <translation>Afficher l'image entière (F)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="213" />
            <source>Open table…</source>
            <translation>Ouvrir une table…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="215" />
            <source>Save table…</source>
            <translation>Enregistrer la table…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="215" />
            <source>Save the observation table (CSV)</source>
            <translation>Enregistrer la table des observations (CSV)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="218" />
            <source>Save gcp_list…</source>
            <translation>Enregistrer gcp_list…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="218" />
            <source>Save as ODM gcp_list.txt</source>
            <translation>Enregistrer au format ODM gcp_list.txt</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="221" />
            <source>Add table layer</source>
            <translation>Ajouter une couche table</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="222" />
            <source>Keep the measurements as a table layer in the project: the saved CSV table, rewritten as you measure (a temporary layer until a table is saved)</source>
            <translation>Conserver les mesures comme couche table dans le projet : la table CSV enregistrée, réécrite au fil des mesures (une couche temporaire tant qu'aucune table n'est enregistrée)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="280" />
            <source>Choose the folder of the photos first.</source>
            <translation>Choisissez d'abord le dossier des photos.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="283" />
            <source>Choose a GCP point layer first (fields: name, optional role and z).</source>
            <translation>Choisissez d'abord une couche de points d'appui (champs : name, role et z facultatifs).</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="308" />
            <source>{} GCPs, {} images</source>
            <translation>{} points d'appui, {} images</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="451" />
            <source>Load the images and the GCPs first.</source>
            <translation>Chargez d'abord les images et les points d'appui.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="479" />
            <source>Refining needs an orientation: choose one and load again.</source>
            <translation>L'affinage nécessite une orientation : choisissez-en une et rechargez.</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="490" />
            <source>{} refined in {} images</source>
            <translation>{} affiné dans {} images</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="636" />
            <source>GCP observations</source>
            <translation>Observations des points d'appui</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="310" />
            <source>; {} predicted positions</source>
            <translation> ; {} positions prédites</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="492" />
            <source>; not in {}</source>
            <translation> ; pas dans {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="538" />
            <source>{} on {}: {} — {} measured, {} to do — zoom {:.2f}</source>
            <translation>{} sur {} : {} — {} mesurées, {} à faire — zoom {:.2f}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="331" />
            <source>{}: X {:.3f}, Y {:.3f}, Z {:.3f}{}</source>
            <translation>{} : X {:.3f}, Y {:.3f}, Z {:.3f}{}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="332" />
            <source> (check point)</source>
            <translation> (point de contrôle)</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="487" />
            <source>Refinement failed: {}</source>
            <translation>Échec de l'affinage : {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="487" />
            <source>no image matched</source>
            <translation>aucune image appariée</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="592" />
            <source>Saved {} measurements to {}</source>
            <translation>{} mesures enregistrées dans {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="617" />
            <source>Loaded {} measurements from {}</source>
            <translation>{} mesures chargées depuis {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="289" />
            <source>GCP layer {!r} has no point</source>
            <translation>La couche de points d'appui {!r} ne contient aucun point</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="393" />
            <source>Cannot read the image {}</source>
            <translation>Impossible de lire l'image {}</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/gcp_panel.py" line="638" />
            <source>Cannot open {} as a table layer</source>
            <translation>Impossible d'ouvrir {} comme couche table</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="15" />
            <source>&amp;TruOrtho</source>
            <translation>&amp;TruOrtho</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="18" />
            <source>Photos to true orthophoto (whole pipeline)…</source>
            <translation>Des photos à l'orthophoto vraie (chaîne complète)…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="19" />
            <source>Orient images…</source>
            <translation>Orienter les images…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="20" />
            <source>Dense matching (OSGM)…</source>
            <translation>Appariement dense (OSGM)…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="21" />
            <source>Filter DSM…</source>
            <translation>Filtrer le MNS…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="22" />
            <source>DSM to mesh…</source>
            <translation>MNS en maillage…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="23" />
            <source>True orthophoto…</source>
            <translation>Orthophoto vraie…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="105" />
            <source>GCP measurements in photos…</source>
            <translation>Mesures des points d'appui dans les photos…</translation>
        </message>
        <message>
            <location filename="../truortho_plugin/plugin.py" line="133" />
            <source>The algorithm {} is not available in this version.</source>
            <translation>L'algorithme {} n'est pas disponible dans cette version.</translation>
        </message>
        <message>
            <source>none: one nadir reference system (the DSM). auto: groups of oblique images also get reference systems along their viewing directions, whose points go to the point cloud with their 'system' id.</source>
            <translation type="obsolete">none : un seul système de référence au nadir (le MNS). auto : les groupes d'images obliques reçoivent en plus des systèmes de référence orientés selon leurs directions de visée, dont les points vont dans le nuage de points avec leur identifiant 'system'.</translation>
        </message>
        <message>
            <source>Computes a true orthophoto from oriented images and a surface (a DSM raster such as OSGM's, or a PLY/OBJ mesh): every cell is coloured from an image that really sees it, found with a depth buffer of the surface per image (DSM cells as flat tops with vertical walls at height steps, or the mesh's triangles; frustum and back-face culling). Among the images that see a cell the one with the finest effective ground resolution (distance and incidence on the surface) is preferred; roofs are textured from one image each and seamlines follow height discontinuities and avoid places where the images disagree (label smoothing), with feathering across seams only between images that both see the cells. Per-image colour corrections in CIE L*a*b* (per-band gain/offset for non-RGB data) are estimated by least squares from cells seen by several images. Cells no image sees get alpha 0 and appear in the occlusion mask. Any band count and data type of the images is kept (RGB, 16-bit panchromatic, thermal). Processing runs by tiles with bounded memory; progress and cancel per tile.</source>
            <translation type="obsolete">Calcule une orthophoto vraie à partir d'images orientées et d'une surface (un raster MNS comme celui d'OSGM, ou un maillage PLY/OBJ) : chaque cellule est colorée à partir d'une image qui la voit réellement, déterminée avec un tampon de profondeur de la surface par image (cellules du MNS comme sommets plats avec murs verticaux aux sauts de hauteur, ou les triangles du maillage ; élimination hors du champ de vue et des faces arrière). Parmi les images qui voient une cellule, celle de résolution au sol effective la plus fine (distance et incidence sur la surface) est préférée ; les toits sont texturés chacun à partir d'une seule image et les lignes de raccord suivent les discontinuités de hauteur et évitent les endroits où les images divergent (lissage des étiquettes), avec un fondu à travers les raccords uniquement entre images qui voient toutes deux les cellules. Des corrections colorimétriques par image dans CIE L*a*b* (gain/décalage par bande pour les données non RVB) sont estimées par moindres carrés à partir des cellules vues par plusieurs images. Les cellules qu'aucune image ne voit reçoivent un alpha de 0 et apparaissent dans le masque d'occultation. Le nombre de bandes et le type de données des images sont conservés (RVB, panchromatique 16 bits, thermique). Le traitement se fait par tuiles avec une mémoire bornée ; progression et annulation par tuile.</translation>
        </message>
        <message>
            <source>Height step between two search planes, metres; empty or 0 = the resolution.</source>
            <translation type="obsolete">Pas de hauteur entre deux plans de recherche, en mètres ; vide ou 0 = la résolution.</translation>
        </message>
        <message>
            <source>Number of aggregation directions of semi-global matching: 8 (faster) or 16 (smoother slanted surfaces).</source>
            <translation type="obsolete">Nombre de directions d'agrégation de l'appariement semi-global : 8 (plus rapide) ou 16 (surfaces inclinées plus lisses).</translation>
        </message>
        <message>
            <source>Imports the orientation of an image block (interior and exterior orientation of every image, sparse points) from COLMAP, Orthority or OpenSfM/ODM files into TruOrtho's orientation JSON, and writes a layer of projection centres and a layer of image footprints. Conventions (camera axes, rotations, pixel origin) are converted at import; see the README, 'Formats and conventions'.</source>
            <translation type="obsolete">Importe l'orientation d'un bloc d'images (orientation interne et externe de chaque image, points épars) depuis des fichiers COLMAP, Orthority ou OpenSfM/ODM dans le JSON d'orientation de TruOrtho, et écrit une couche des centres de projection et une couche des emprises des images. Les conventions (axes de la caméra, rotations, origine des pixels) sont converties à l'import ; voir le README, 'Formats and conventions'.</translation>
        </message>
        <message>
            <source>Keep the measurements as a table layer in the project</source>
            <translation type="obsolete">Conserver les mesures comme couche table dans le projet</translation>
        </message>
        <message>
            <source>Reports the versions of QGIS, GDAL, rasterio, numpy, numba, OpenCV and pyproj that TruOrtho runs with, and writes them to a JSON file. Fails if rasterio is linked to a different GDAL than QGIS.</source>
            <translation type="obsolete">Indique les versions de QGIS, GDAL, rasterio, numpy, numba, OpenCV et pyproj avec lesquelles TruOrtho fonctionne et les écrit dans un fichier JSON. Échoue si rasterio est lié à une autre version de GDAL que QGIS.</translation>
        </message>
        <message>
            <source>Projection centres as PointZ with name, camera, x, y, z, omega, phi, kappa (degrees).</source>
            <translation type="obsolete">Centres de projection en PointZ avec name, camera, x, y, z, omega, phi, kappa (degrés).</translation>
        </message>
        <message>
            <source>HTML report (and a JSON file of the same name): sigma0, image RMS, per-image residuals, GCP and check point tables, residual vector plots, tie-point multiplicity histogram, block overview.</source>
            <translation type="obsolete">Rapport HTML (et un fichier JSON du même nom) : sigma0, EMQ image, résidus par image, tables des points d'appui et de contrôle, graphiques des vecteurs résidus, histogramme de multiplicité des points de liaison, vue d'ensemble du bloc.</translation>
        </message>
        <message>
            <source>Projection centres (PointZ) with omega, phi, kappa.</source>
            <translation type="obsolete">Centres de projection (PointZ) avec omega, phi, kappa.</translation>
        </message>
        <message>
            <source>Folder of the products (created when missing; existing products are replaced).</source>
            <translation type="obsolete">Dossier des produits (créé s'il manque ; les produits existants sont remplacés).</translation>
        </message>
        <message>
            <source>Exports a DSM as a point cloud, one point per valid cell centre, with colours from an orthoimage and per-point confidence from a confidence raster: LAS 1.4 or LAZ (point format 7, CRS as WKT, extra dimensions 'confidence' and 'system' (the reference system), a TruOrtho VLR describing the reference systems), readable by PDAL, laspy, LAStools and CloudCompare. An Entwine Point Tile (EPT) dataset is written beside it: QGIS builds without PDAL (as Debian's QGIS 3.22) open it as a point cloud layer (Layer &gt; Add Layer &gt; Point Cloud, choose ept.json).</source>
            <translation type="obsolete">Exporte un MNS en nuage de points, un point par centre de cellule valide, avec les couleurs d'une orthoimage et une confiance par point issue d'un raster de confiance : LAS 1.4 ou LAZ (format de point 7, SCR en WKT, dimensions supplémentaires 'confidence' et 'system' (le système de référence), un VLR TruOrtho décrivant les systèmes de référence), lisible par PDAL, laspy, LAStools et CloudCompare. Un jeu de données Entwine Point Tile (EPT) est écrit à côté : les versions de QGIS sans PDAL (comme le QGIS 3.22 de Debian) l'ouvrent comme couche nuage de points (Couche &gt; Ajouter une couche &gt; Nuage de points, choisir ept.json).</translation>
        </message>
        <message>
            <source>GeoTIFF with the images' bands and data type plus an alpha band, tiled, with overviews, Cloud-Optimized GeoTIFF layout.</source>
            <translation type="obsolete">GeoTIFF avec les bandes et le type de données des images plus une bande alpha, tuilé, avec aperçus, au format Cloud-Optimized GeoTIFF.</translation>
        </message>
    </context>
</TS>
